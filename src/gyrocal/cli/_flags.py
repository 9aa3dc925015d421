"""Library parameter names and the command-line flags that set them.

Library errors name the Python parameter at fault (``GyrocalError.param``); the error
boundary shows the flag instead, through :func:`flag`. A test checks that every
``param=`` the library raises with is either here or in :data:`NOT_FLAGS`.
"""

from __future__ import annotations

__all__ = ["FLAGS", "NOT_FLAGS", "flag"]

#: Python parameter -> flag.
FLAGS: dict[str, str] = {
    # reading
    "units": "--units",
    "columns": "--columns",
    "skip_rows": "--skip-rows",
    "time_units": "--time-units",
    "nan": "--nan",
    # plan
    "target_scale": "--target-scale",
    "target_bias": "--target-bias",
    "target_cross": "--target-cross",
    "target_accel_scale": "--target-accel-scale",
    "target_accel_offset": "--target-accel-offset",
    "max_speed": "--max-speed",
    "sample_rate": "--sample-rate",
    "sensitivity": "--sensitivity",
    "output_units": "--output-units",
    "topic": "--topic",
    "saturation": "--saturation",
    "check_units": "--no-unit-check",
    "full_scale": "--full-scale",
    "accel_units": "--accel-units",
    "accel_sensitivity": "--accel-sensitivity",
    "gravity": "--gravity",
    # calibrate
    "speed": "--speed",
    "angle": "--angle",
    "windows": "--windows",
    "method": "--method",
    "noise_std": "--noise-std",
    "noise_density": "--noise-density",
    "accept_implausible": "--accept-implausible",
    # imu
    "accel_model": "--accel-model",
    "gyro_model": "--gyro-model",
    "g_sensitivity": "--g-sensitivity",
    "min_static": "--min-static",
    "accel_output_units": "--accel-output-units",
    "accel_log": "--accel-log",
    "accel_columns": "--accel-columns",
    # apply, export
    "model": "--model",
    "out_of_range": "--out-of-range",
    "temp_tau": "--temp-tau",
    "fmt": "--format",
    "prefix": "--prefix",
    # thermal
    "settle": "--settle",
    "temp_tolerance": "--temp-tolerance",
    "reference_temp": "--ref-temp",
    "max_order": "--max-order",
    # simulate
    "turns": "--turns",
    "wait": "--wait",
    "ramp": "--ramp",
    "vibration": "--vibration",
    "misalignment_deg": "--misalignment",
    "temps": "--temps",
    "soak": "--temp-soak",
    "temp_soak": "--temp-soak",
    "temp_range": "--temp-range",
    "points": "--temp-points",
    "temp_hysteresis": "--temp-hysteresis",
    "rates": "--rates",
    "step_duration": "--step-duration",
    "temp_noise": "--temp-noise",
    "temp_quantum": "--temp-quantum",
    "duration": "--duration",
    "quantum": "--quantum",
    "rate_random_walk": "--rrw",
    "bias_instability": "--bias-instability",
    "revolutions": "--revolutions",
    "ripple": "--ripple",
    "ripple_freq": "--ripple-freq",
    "temp_start": "--temp-start",
    "temp_end": "--temp-end",
    "pause": "--wait",
    # simulate --protocol multi-position, plan --design poses
    "poses": "--poses",
    "turn_deg": "--tilt",
    "static_duration": "--still",
    "peak_rate_deg": "--peak-rate",
    "stamps": "--stamps",
    "gaps": "--gaps",
    # noise, thermal-bias, flight and VIO exports
    "imu": "--imu",
    "motion": "--motion",
    "min_span": "--min-span",
    "inflate": "--inflate",
    "rostopic": "--rostopic",
    "update_rate": "--update-rate",
    "accel_noise_density": "--accel-noise-density",
    "accel_random_walk": "--accel-random-walk",
    "gyro_random_walk": "--gyro-random-walk",
    "use_bound": "--random-walk-bound",
    "slot": "--slot",
    "device_id": "--device-id",
    "accel_device_id": "--accel-device-id",
    "caltemp": "--caltemp",
    "name": "--name",
    # capture, simulate --device
    "port": "--port",
    "baud": "--baud",
    "wire": "--wire",
    "samples": "--samples",
    "silence": "--silence",
    "guide": "--guide",
    "hold": "--hold",
    "faults": "--faults",
    "pace": "--pace",
    "write_back_timeout": "--write-back-timeout",
    # simulate --reference (a reference gyro's log) and verify, whose reading flags for the reference
    # carry the prefix ref_ (see cli/_reading.py: prefixed_params)
    "reference": "--reference",
    "time_offset_s": "--ref-offset",
    "clock_drift_ppm": "--ref-drift",
    "mounting_deg": "--ref-mounting",
    "ref_noise_std": "--ref-noise",
    "ref_units": "--ref-units",
    "ref_columns": "--ref-columns",
    "ref_skip_rows": "--ref-skip-rows",
    "ref_sample_rate": "--ref-sample-rate",
    "ref_sensitivity": "--ref-sensitivity",
    "ref_topic": "--ref-topic",
    "ref_saturation": "--ref-saturation",
    "ref_check_units": "--ref-no-unit-check",
    "fit_drift": "--no-drift",
    "stretch": "--stretch",
    "tolerance": "--tolerance",
}

#: Parameters that library errors name but that no flag sets (the command line fills them itself).
NOT_FLAGS: frozenset[str] = frozenset({
    "accel_source_units", "covariance", "correction", "accelerometer", "fit", "observed",
    "chi2", "dof", "p_value", "birge_ratio", "covariance_scaled", "residuals", "warnings", "noise_std_axes",
    "max_abs_rate", "mounting_rotation", "accel_noise_std", "targets",
    "reference_sd",  # --angle-sd or --speed-sd, checked and converted by the command
})


def flag(param: str) -> str:
    """The flag that sets library parameter `param` (the parameter's own name when no flag does)."""
    return FLAGS.get(param, param)
