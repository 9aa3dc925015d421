"""The poses of a hand session on the sphere, and the misfit of each turn between them."""

from __future__ import annotations

import numpy as np

from .figure import new_figure

__all__ = ["draw_pairs", "draw_poses", "poses_figure"]


def _arc(a: np.ndarray, b: np.ndarray, n: int = 24) -> np.ndarray:
    """Points (n, 3) on the great circle from unit vector `a` to `b`."""
    omega = np.arccos(np.clip(a @ b, -1.0, 1.0))
    if omega < 1e-6:
        return np.stack([a, b])
    s = np.linspace(0.0, 1.0, n)[:, None]
    return (np.sin((1 - s) * omega) * a + np.sin(s * omega) * b) / np.sin(omega)


def draw_poses(ax, directions: np.ndarray, *, disagree=(), empty_cap=None) -> dict:
    """Draw unit gravity directions (n, 3) on a wire sphere in a 3-D `ax`, joined in time order.

    Poses are numbered; the move into a pose whose pair disagrees (indices in `disagree`, of the
    first pose of the pair) is drawn red; `empty_cap` ``(centre (3,), radius_deg)`` is outlined.
    Returns the artists by name.
    """
    d = np.asarray(directions, dtype=float)
    u, v = np.mgrid[0:2 * np.pi:25j, 0:np.pi:13j]
    sphere = ax.plot_wireframe(np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.85", linewidth=0.5)
    moves = []
    for i in range(len(d) - 1):
        arc = _arc(d[i], d[i + 1])
        moves += ax.plot(*arc.T, color="tab:red" if i in set(disagree) else "tab:blue", linewidth=1.2)
    points = ax.scatter(*d.T, c=np.arange(len(d)), cmap="viridis", s=40, depthshade=False)
    labels = [ax.text(*(1.08 * p), str(i + 1), fontsize=7) for i, p in enumerate(d)]
    cap = []
    if empty_cap is not None:
        centre, radius = np.asarray(empty_cap[0], dtype=float), np.radians(empty_cap[1])
        e1 = np.cross(centre, [1.0, 0.0, 0.0] if abs(centre[0]) < 0.9 else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(centre, e1)
        phi = np.linspace(0, 2 * np.pi, 60)[:, None]
        ring = centre * np.cos(radius) + (e1 * np.cos(phi) + e2 * np.sin(phi)) * np.sin(radius)
        cap = ax.plot(*ring.T, color="tab:orange", linestyle="--", linewidth=1.0)
    for name, axis in (("x", 0), ("y", 1), ("z", 2)):
        end = np.eye(3)[axis] * 1.3
        ax.plot(*np.stack([-end, end]).T, color="0.5", linewidth=0.6)
        ax.text(*end, name, color="0.3")
    ax.set_box_aspect((1, 1, 1), zoom=1.35)
    ax.set_axis_off()
    return {"sphere": sphere, "moves": moves, "points": points, "labels": labels, "empty_cap": cap}


def draw_pairs(ax, checks) -> dict:
    """Bars of each pose pair's (and turn's) misfit [deg], disagreeing ones red, in `ax`."""
    labels = [c.label for c in checks]
    misfit = [c.residual_deg for c in checks]
    colors = ["tab:red" if c.disagrees else "tab:blue" for c in checks]
    bars = ax.bar(np.arange(len(checks)), misfit, color=colors)
    ax.set_xticks(np.arange(len(checks)), labels, rotation=90, fontsize=7)
    ax.set_ylabel("misfit [deg]")
    ax.set_title("turns between poses: integrated gyro against the gravity directions", fontsize=9)
    return {"bars": bars}


def poses_figure(result, *, title: str = "", fig=None):
    """The poses on the sphere (left) and each turn's misfit (right) of an
    :class:`~gyrocal.imu.ImuCalibrationResult`."""
    fig = fig or new_figure((13.0, 6.0), layout="constrained")
    grid = fig.add_gridspec(1, 2, width_ratios=(1.3, 1.0))
    ax3 = fig.add_subplot(grid[0], projection="3d")
    cov = result.coverage
    disagree = [c.poses[0] for c in result.gyro.checks if c.kind == "pair" and c.disagrees]
    draw_poses(ax3, result.accel.directions, disagree=disagree,
               empty_cap=(cov.empty_cap_centre, cov.empty_cap_deg))
    ax3.set_title(f"{len(result.statics)} still poses, {cov.poses} distinct; spread {cov.spread:.2f} of 1, "
                  f"largest empty cap {cov.empty_cap_deg:.0f} deg (dashed)", fontsize=9)
    draw_pairs(fig.add_subplot(grid[1]), result.gyro.checks)
    if title:
        fig.suptitle(title)
    return fig
