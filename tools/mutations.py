"""The mutations of :mod:`mutants`: one line each of the code behind an estimate or its 1-sigma.

Each changes what a correct suite must notice: a term dropped, a constant about 1 % off, a factor
not squared, an off-by-one. ``tests`` are the files tried first (the likely killers); the rest of
the suite runs after them.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Mutation:
    name: str
    path: str
    old: str
    new: str
    why: str
    tests: tuple[str, ...] = ()


S = "src/gyrocal/"
FM = S + "estimators/first_moment.py"
EX6 = S + "estimators/_exact6.py"
RAMP, LIM, TM, GJ = (S + "imu/" + f for f in ("ramp.py", "thermal_limits.py", "thermal_model.py", "_gyro_jac.py"))
IMU_RAMP = ("tests/test_imu_ramp.py",)
IMU_LIM = ("tests/test_imu_thermal_limits.py", "tests/test_imu_thermal_sim.py")
PIN_LIM = ("tests/test_pins.py",) + IMU_LIM
IMU_TM = ("tests/test_pins.py", "tests/test_imu_thermal.py", "tests/test_imu_thermal_sim.py", "tests/test_imu_thermal_limits.py")
GJ_TESTS = ("tests/test_imu_gyro_jacobian.py",)
SEL = ("tests/test_pins.py", "tests/test_selfcheck.py", "tests/test_realistic.py", "tests/test_estimators.py")
MUTATIONS = [
    # estimators: the first-moment rows, weights and sandwich covariance
    Mutation("fm-rot-weight", FM, "w_rot = np.sqrt(obs.count[rot])[None, :, None]",
             "w_rot = np.sqrt(obs.count[rot] + 1)[None, :, None]", "rotation rows weighted sqrt(n + 1)",
             ("tests/test_estimators.py",)),
    Mutation("fm-static-weight", FM, "w_sta = np.sqrt(obs.count[sta])[None, :, None]",
             "w_sta = (obs.count[sta] ** 0.49)[None, :, None]", "static rows weighted n^0.49", SEL),
    Mutation("fm-jacobian-b", FM, "J_rot = np.concatenate([u * (obs.mean[:, rot] + b), u * k], axis=-1) * w_rot",
             "J_rot = np.concatenate([u * (obs.mean[:, rot] + b), u], axis=-1) * w_rot",
             "the bias column of a turn's Jacobian without k", SEL),
    Mutation("fm-rate-var", FM, "extra[:n_rot] = (obs.count * obs.rate_var)[~obs.static]",
             "extra[:n_rot] = (obs.rate_var)[~obs.static]", "a reference's variance not times the count", SEL),
    Mutation("fm-sandwich", FM, "return Hinv @ meat @ Hinv", "return Hinv", "the sandwich's meat dropped", SEL),
    Mutation("fm-mean-var", FM, "nu = np.where(np.isnan(obs.mean_var), nu, obs.mean_var * obs.count[None, :, None])",
             "nu = np.where(np.isnan(obs.mean_var), nu, obs.mean_var * 1.02 * obs.count[None, :, None])",
             "a measured window-mean variance 2 % high", SEL),
    Mutation("noise-pool", S + "estimators/_noise.py", "w = (a < top[:, None]) * count[:, None, None]",
             "w = (a <= top[:, None]) * count[:, None, None]", "the rotating axis's noise pooled in",
             ("tests/test_estimators.py", "tests/test_pipeline.py")),
    Mutation("exact6-noise", EX6, "q = 4 * np.einsum(", "q = 3.96 * np.einsum(",
             "closed form: the variance of F 1 % low", ("tests/test_estimators.py", "tests/test_fast_path.py")),
    Mutation("exact6-b", EX6, "k, b = np.sqrt(beta[:3]), beta[3:] / (2 * beta[:3])",
             "k, b = np.sqrt(beta[:3]), beta[3:] / (2.02 * beta[:3])", "closed form: b 1 % low",
             ("tests/test_estimators.py",)),
    # moments of a window
    Mutation("moments-noise", S + "observations/moments.py", "noise / (count - 1)[:, None] / 2.0",
             "noise / count[:, None] / 2.0", "first-difference noise over n, not n - 1",
             ("tests/test_estimators.py", "tests/test_observations.py")),
    # the extra variances (Paule-Mandel)
    Mutation("excess-t-factor", S + "checks/excess.py", "return dof / (dof - 2) if dof > 6 else 1.5",
             "return 1.0 if dof > 6 else 1.5", "Student's t factor dropped", SEL),
    Mutation("excess-t-cap", S + "checks/excess.py", "return dof / (dof - 2) if dof > 6 else 1.5",
             "return dof / (dof - 2) if dof > 6 else 1.0", "no t factor at few degrees of freedom", SEL),
    Mutation("excess-evidence", S + "checks/excess.py", "EVIDENCE_P = 0.1", "EVIDENCE_P = 0.01",
             "evidence threshold 0.1 -> 0.01", SEL),
    Mutation("excess-leverage", S + "checks/excess.py", "dof = float(np.sum(1 - h[rows]))", "dof = float(len(h[rows]))",
             "degrees of freedom without the leverages", SEL),
    Mutation("excess-turn-angle", S + "checks/excess.py", "c_turn = count_rot / obs.duration[rot] ** 2 if",
             "c_turn = count_rot / obs.duration[rot] if", "an angle's extra variance not over T^2", SEL),
    Mutation("excess-solve", S + "checks/excess.py", "        if float(np.sum(r2 / (v + c * mid))) > dof:",
             "        if float(np.sum(r2 / (v + c * mid))) > 1.02 * dof:", "chi2 solved for 1.02 dof", SEL),
    # the paper's methods: Birge scaling
    Mutation("birge-not-squared", S + "checks/fit.py", "fit.covariance * quality.birge_ratio**2",
             "fit.covariance * quality.birge_ratio", "Birge ratio not squared", SEL),
    Mutation("quality-threshold", S + "checks/quality.py", "P_THRESHOLD = 1e-3", "P_THRESHOLD = 1e-4",
             "flag threshold 1e-3 -> 1e-4", SEL + ("tests/test_cli_selfcheck.py",)),
    Mutation("quality-dof", S + "checks/quality.py", "dof = rows - n_params", "dof = rows - n_params + 1",
             "one degree of freedom too many", SEL),
    # gaps hidden inside a turn
    Mutation("gap-variance-10", S + "segmentation/screening.py", "(bound / turned) ** 2 / 3.0", "(bound / turned) ** 2 / 30.0",
             "the gap variance divided by 10", SEL),
    Mutation("gap-noise-term", S + "segmentation/screening.py",
             "/ 2 + 3 * noise * math.sqrt(1 / len(ra) + 1 / len(rb))", "/ 2",
             "the gap bound without its noise term", SEL),
    Mutation("reference-sd", S + "segmentation/screening.py", "rel += (reference_sd / size) ** 2",
             "rel += (reference_sd / size) ** 2 / 2", "the declared angle accuracy halved in variance", SEL),
    # long-run variances of window means
    Mutation("nw-bartlett", S + "observations/longrun.py", "s = s + 2 * (1 - h / (lags + 1)) *", "s = s + 2 * (1 - h / lags) *",
             "Bartlett weights off by one", ("tests/test_fast_paths.py",) + SEL),
    Mutation("nw-recolour", S + "observations/longrun.py", "return np.maximum(s, 0.0) / (1.0 - rho) ** 2 / n",
             "return np.maximum(s, 0.0) / (1.0 - rho) / n", "prewhitening not recoloured by (1 - rho)^2",
             ("tests/test_fast_paths.py",) + SEL),
    Mutation("span-shrink", S + "observations/longrun.py", "shrink += len(d) * (1 - L / len(r))", "shrink += len(d)",
             "a window's own mean not removed from its span sums", ("tests/test_fast_paths.py",) + SEL),
    Mutation("span-mean-var", S + "observations/window_stats.py", "b * fits[i][1] + a * fits[i][1] ** 2",
             "b * fits[i][1] + a * fits[i][1]", "a plateau mean's correlated term not squared",
             ("tests/test_fast_paths.py",) + SEL),
    Mutation("pooled-lrv", S + "observations/window_stats.py", "return newey_west_var(chosen) * len(chosen)",
             "return newey_west_var(chosen) * (len(chosen) - 1)", "pooled long-run variance over n - 1",
             ("tests/test_fast_paths.py",) + SEL),
    # time base
    Mutation("period-block", S + "recording/timebase.py", "return float(np.median(np.diff(ends))) / block",
             "return float(np.mean(np.diff(ends))) / block", "period from the mean of block steps (gaps pull it)",
             ("tests/test_timebase.py", "tests/test_fast_paths.py")),
    Mutation("timegaps-rise", S + "recording/timegaps.py", "rise = np.flatnonzero(np.diff(floor) >= 0.5 * period)",
             "rise = np.flatnonzero(np.diff(floor) >= 1.5 * period)", "a gap needs a rise of 1.5 periods",
             ("tests/test_timebase.py", "tests/test_fast_paths.py")),
    Mutation("least-delayed", S + "recording/timegaps.py", "    k = len(x) // 10\n", "    k = len(x) // 5\n",
             "least-delayed level at the fifth, not tenth, quantile",
             ("tests/test_timebase.py", "tests/test_fast_paths.py")),
    # MAD and stillness
    Mutation("mad-constant", S + "constants.py", "MAD_TO_SIGMA = ", "MAD_TO_SIGMA = 1.01 * ", "MAD factor x 1.01",
             ("tests/test_pins.py",)),
    Mutation("difference-half", S + "_white.py", "np.mean(d * d, axis=axis) / 2.0", "np.mean(d * d, axis=axis) / 2.2",
             "the first-difference white variance 10 % low", ("tests/test_white_difference.py",)),
    Mutation("difference-robust-sqrt2", S + "_white.py", "axis=axis) / math.sqrt(2.0)", "axis=axis)",
             "the robust first-difference sigma without 1/sqrt 2", ("tests/test_white_difference.py",)),
    Mutation("stillness-jump", S + "segmentation/stillness.py", "nsigma * np.sqrt(2.0) * scale", "nsigma * scale",
             "a jump between blocks judged without sqrt 2", ("tests/test_pins.py", "tests/test_stillness.py",)),
    Mutation("quiet-noise", S + "observations/observed.py", "var(axis=1, ddof=1)", "var(axis=1, ddof=0)",
             "quiet-block noise variance with ddof 0", ("tests/test_pins.py", "tests/test_cli_newcomer.py", "tests/test_cli_selfcheck.py")),
    # noise figures
    Mutation("whitenoise-constant", S + "verify/whitenoise.py", "_MAD_VARIANCE = 1.977", "_MAD_VARIANCE = 1.997",
             "second-difference MAD variance 1 % high", ("tests/test_pins.py", "tests/test_verify_metrics.py")),
    Mutation("whitenoise-weights", S + "verify/whitenoise.py", "np.sqrt(1.0 + lam**2 + (1.0 - lam) ** 2)",
             "np.sqrt(1.0 + lam**2)", "second differences normalised without one neighbour",
             ("tests/test_verify_metrics.py",)),
    Mutation("bias-instability", S + "noise/figures.py", "BI_FACTOR = math.sqrt(2.0 * math.log(2.0) / math.pi)",
             "BI_FACTOR = 0.5", "bias-instability factor 0.5", ("tests/test_pins.py", "tests/test_noise.py")),
    Mutation("white-line-corr", S + "noise/white.py", "var = float(w @ (_rho(lt[sl]) * np.outer(s[sl], s[sl])) @ w)",
             "var = float(w @ (np.eye(len(w)) * np.outer(s[sl], s[sl])) @ w)",
             "the density fit's points taken as independent", ("tests/test_noise_white.py", "tests/test_noise.py")),
    Mutation("white-line-slope", S + "noise/white.py", "(np.log(adev[sl]) + 0.5 * lt[sl])",
             "(np.log(adev[sl]) + 0.49 * lt[sl])", "the density line's slope -0.49, not -1/2",
             ("tests/test_noise_white.py", "tests/test_noise.py")),
    Mutation("random-walk", S + "noise/figures.py", "walk = none if i is None else at(i, -2, math.sqrt(3.0 / taus[i]))",
             "walk = none if i is None else at(i, -2, math.sqrt(2.9 / taus[i]))", "rate random walk 1.7 % low",
             ("tests/test_pins.py", "tests/test_noise.py",)),
    Mutation("allan-edf", S + "noise/figures.py", "mult = 3.0 if pooled else 1.0", "mult = 3.0 if pooled else 1.5",
             "an axis's Allan points with 1.5x their degrees of freedom", ("tests/test_noise.py",)),
    # thermal: the full-temperature-range method and the thermal-bias curve
    Mutation("thermal-point-dof", S + "thermal/fit.py", "dof = max(len(ref) - 4, 1)", "dof = max(len(ref) - 3, 1)",
             "a temperature point's residual dof one too many", ("tests/test_pins.py", "tests/test_thermal_fit.py",)),
    Mutation("thermal-point-noise", S + "thermal/fit.py", "var_noise = (H ** 2) @", "var_noise = H @",
             "noise-propagated variance with H, not H^2", ("tests/test_thermal_fit.py",)),
    Mutation("smooth-one-se", S + "thermal/smooth.py", "best * (1 + 1 / np.sqrt(2 * len(t)))",
             "best * (1 + 1 / np.sqrt(len(t)))", "LOTO order rule with 1/sqrt(n)",
             ("tests/test_pins.py", "tests/test_thermal_model.py", "tests/test_thermal_lagrange.py")),
    Mutation("polyfit-one-se", S + "flight/polyfit.py", "best * (1 + 1 / math.sqrt(2 * n_segments))",
             "best * (1 + 1 / math.sqrt(n_segments))", "thermal-bias order rule with 1/sqrt(K)",
             ("tests/test_pins.py", "tests/test_thermal_bias.py")),
    Mutation("ar1-white", S + "flight/polyfit.py", "cov = white_var * B + s2 * C", "cov = s2 * C + 0 * B",
             "the thermal-bias covariance without its white term", ("tests/test_thermal_bias.py",)),
    Mutation("ar1-phi-grid", S + "flight/polyfit.py", "np.linspace(0.0, 0.995, 100)[1:]",
             "np.linspace(0.0, 0.5, 100)[1:]", "wander correlation searched only up to 0.5",
             ("tests/test_thermal_bias.py",)),
    # design: the Cramér-Rao bound
    Mutation("crb-row-var", S + "planning/design.py", "row_var = np.einsum(\"bmj,j->bm\", S * S, nv)",
             "row_var = np.einsum(\"bmj,j->bm\", S * S, nv) * 1.02", "Fisher information 2 % low",
             ("tests/test_design.py", "tests/test_planning.py")),
    Mutation("crb-density", S + "planning/design.py", "np.asarray(noise_density, dtype=float) * math.sqrt(sample_rate)",
             "np.asarray(noise_density, dtype=float) * math.sqrt(sample_rate / 2)", "density to noise without 2",
             ("tests/test_design.py", "tests/test_planning.py")),
    # what b's 1-sigma covers, and the turns' own long-run noise (no static window)
    Mutation("earth-rate", S + "checks/noise_terms.py", "_EARTH_SD = EARTH_RATE / math.sqrt(3.0)",
             "_EARTH_SD = EARTH_RATE / math.sqrt(6.0)", "the Earth's rate's projection halved in variance",
             ("tests/test_realistic_sigma.py", "tests/test_pins.py")),
    Mutation("white-floor", S + "observations/window_stats.py", "mean_var=np.maximum(o.mean_var, var / o.count)",
             "mean_var=o.mean_var", "a given white level no floor on measured variances",
             ("tests/test_realistic_sigma.py", "tests/test_pipeline.py")),
    Mutation("turns-lrv", S + "observations/window_stats.py", "* sum(map(len, r)) if r else np.nan",
             "* sum(map(len, r)) / 4 if r else np.nan", "the turns' long-run variance a quarter",
             ("tests/test_realistic_sigma.py",)),
    # the station's verdict: the guard band
    Mutation("guard-band", S + "station/accept.py", "reach = self.guard * self.sigma",
             "reach = self.sigma", "the guard band's factor dropped", ("tests/test_station_accept.py",)),
    # the whole IMU across temperature: the ramp's joint accelerometer fit
    Mutation("ramp-order-error", RAMP, "covariance=cov + np.outer(d, d)", "covariance=cov + 0 * np.outer(d, d)",
             "a ramp's lower order chosen without its model error d d^T", IMU_RAMP),
    Mutation("ramp-wald-dof", RAMP, "stats.chi2.sf(wald, prob.m)", "stats.chi2.sf(wald, 2 * prob.m)",
             "the top power's Wald test with twice its degrees of freedom", IMU_RAMP),
    Mutation("ramp-drop-p", RAMP, "DROP_P = 0.05", "DROP_P = 0.5", "the top power kept unless p < 0.5", IMU_RAMP),
    Mutation("ramp-offset-jacobian", RAMP, "d_q = np.column_stack([d_a, -np.einsum(",
             "d_q = np.column_stack([d_a, np.einsum(", "the offset's Jacobian columns with the wrong sign", IMU_RAMP),
    Mutation("ramp-pose-sigma", RAMP, "np.einsum(\"pi,pij->pj\", n, a) ** 2, self.se**2))",
             "np.einsum(\"pi,pij->pj\", n, a) ** 2, self.se**2 * 1.1))", "a pose's variance 10 % high", IMU_RAMP),
    # the limits of a chamber calibration: hysteresis and a lagging temperature sensor
    Mutation("hysteresis-half-width", LIM, "extra = h2 / 4 if", "extra = h2 if",
             "the full, not half, hysteresis width in the 1-sigma", IMU_LIM),
    Mutation("hysteresis-noise-removed", LIM, "(w * (d**2 - var)).sum(axis=0)", "(w * d**2).sum(axis=0)",
             "the branches' noise left in the hysteresis width", PIN_LIM),
    Mutation("hysteresis-chi2-diagonal", LIM, "chi2 = float(sum(x @ np.linalg.solve(v, x) for",
             "chi2 = float(sum(x @ (x / np.diag(v)) for", "the branches' chi-square without the correlations",
             PIN_LIM),
    Mutation("hysteresis-mid-branch", LIM, "return (ph + pc) / 2, (ch + cc) / 4",
             "return (ph + pc) / 2, (ch + cc) / 2", "the mid-branch value's variance not a quarter", PIN_LIM),
    Mutation("drift-slope-sd", LIM, "resid @ resid / max(len(y) - 2, 1) / sxx", "resid @ resid / max(len(y) - 2, 1)",
             "a plateau's drift z against the readings' sd, not the slope's", IMU_LIM),
    Mutation("die-slope", LIM, "den = n * sxx - sx * sx", "den = n * sxx",
             "the die's local slope with the window's mean of t not removed", IMU_RAMP + IMU_LIM),
    # the IMU's temperature model on plateaus: Birge scaling and the order choice
    Mutation("imu-birge-not-rooted", TM, "s = np.repeat(np.sqrt(scale), coefs.shape[1])",
             "s = np.repeat(scale, coefs.shape[1])", "a misfitting top order's variance times (chi2/dof)^2", IMU_TM),
    Mutation("imu-order-error", TM, "cov = cov * np.outer(s, s) + _order_error(", "cov = cov * np.outer(s, s) + 0 * _order_error(",
             "a lower order chosen without its model error d d^T", IMU_TM),
    # the gyro fit's analytic Jacobian (its covariance uses it)
    Mutation("gyro-jac-sigma", GJ, "(prob.lrv * w2 / (3 * sd**2))", "(prob.lrv * w2 / (2 * sd**2))",
             "the noise's derivative in A with 1/2, not 1/3, of the mean squared diagonal", GJ_TESTS),
    Mutation("gyro-jac-coning", GJ, "m[:, 1:] += half * v + cone * np.cross(", "m[:, 1:] += half * v - cone * np.cross(",
             "the coning term's derivative in the later rate with the wrong sign", GJ_TESTS),
    Mutation("gyro-jac-earth", GJ, "+ (EARTH_RATE * prob.turn_time) ** 2 / 3)", "+ (EARTH_RATE * prob.turn_time) ** 2 / 6)",
             "a turn's Earth-rate variance halved in the Jacobian's weights", GJ_TESTS),
    Mutation("gyro-jac-series", GJ, "0.5 - a2 / 24 + a2**2 / 720", "0.5 - a2 / 12 + a2**2 / 720",
             "the right Jacobian's small-angle series with a2/12", GJ_TESTS),
    # the C library's window accumulator and closed form
    Mutation("c-accum-var", S + "c/gyrocal_cal.c", "float var = (acc->s2[i] + acc->c2[i]) / n - m1 * m1;",
             "float var = (acc->s2[i] + acc->c2[i]) / n;", "C: variance without the mean's square",
             ("tests/test_c_native.py", "tests/test_firmware.py")),
    Mutation("c-accum-mean", S + "c/gyrocal_cal.c", "float m1 = (acc->s1[i] + acc->c1[i]) / n;",
             "float m1 = acc->s1[i] / n;", "C: mean without Neumaier's compensation",
             ("tests/test_c_native.py", "tests/test_firmware.py")),
    Mutation("c-return-step", S + "c/gyrocal_cal.c", "k[j] = sqrtf(beta[j]);", "k[j] = beta[j];",
             "C: k without the square root", ("tests/test_c_native.py", "tests/test_firmware.py")),
]
