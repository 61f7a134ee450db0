#!/usr/bin/env python3
"""Plans a grasp with grasp-sim from Python, checks it in physics and plots it (issue 36).

    python3 examples/plan_check_plot.py [MESH] [--units mm] [--out grasp.png]

Without MESH it grasps the thesis cup (assets/objects/cup.stl, in its file's frame). The plot
shows the object's triangles, the palm frame (x red, y green, z blue) and the grasp in words;
matplotlib is optional: without it the script plans and checks, prints, and says it drew nothing.
Needs the package: `pip install .` at the repository root (docs/PYTHON.md).
"""

import argparse
import sys
from pathlib import Path

import numpy as np

import grasp_sim as gs

ROOT = Path(__file__).resolve().parents[1]


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("mesh", nargs="?", help="STL, OBJ, PLY or URDF (default: the thesis cup)")
    ap.add_argument("--units", default="mm", help="mm, cm, inch or m")
    ap.add_argument("--out", default="grasp.png", help="the figure (PNG, SVG, PDF)")
    args = ap.parse_args()

    try:
        if args.mesh:
            obj = gs.Object.from_file(args.mesh, args.units)
        else:
            obj = gs.Object.from_file(ROOT / "assets" / "objects" / "cup.stl", frame="file")
        plan = gs.plan(obj)
        print(f"{obj.name}: {len(obj.faces)} triangles, {obj.info['volume_mm3'] / 1000:.1f} cm^3")
        if plan.grasp is None:
            print(f"ungraspable: {plan.reason}")
            return 1
        print(plan.grasp)
        result = gs.check(obj, plan)
    except gs.GraspSimError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    print(f"physics check: {result.verdict} (object moved {result.translation_mm:.2f} mm, "
          f"turned {result.rotation_deg:.2f} deg relative to the palm)")

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    except ImportError:
        print("matplotlib is not installed: no figure drawn (pip install matplotlib)")
        return 0

    fig = plt.figure(figsize=(7, 7))
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False  # draw the palm frame over the object, not hidden inside it
    tris = obj.vertices[obj.faces]
    ax.add_collection3d(Poly3DCollection(tris, facecolor="0.85", edgecolor="0.6", linewidth=0.1, alpha=0.3, zorder=1))
    pose = plan.grasp.palm_pose
    origin, size = pose[:3, 3], 0.3 * np.ptp(obj.vertices, axis=0).max()
    for k, colour in enumerate(("red", "green", "blue")):
        tip = origin + size * pose[:3, k]
        ax.plot(*zip(origin, tip), color=colour, linewidth=3, zorder=5)
    ax.scatter(*origin, color="black", s=40, label="palm centre (frame: x red, y green, z blue)", zorder=6)
    lo, hi = obj.vertices.min(axis=0), obj.vertices.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2 + size
    for axis, c in zip("xyz", centre):
        getattr(ax, f"set_{axis}lim")(c - half, c + half)
        getattr(ax, f"set_{axis}label")(f"{axis} [mm]")
    angles = ", ".join(f"{t1:.0f}/{t2:.0f}" for t1, t2 in plan.grasp.joint_angles_deg)
    ax.set_title(f"{obj.name}: {result.verdict}; θ1/θ2 {angles} deg; pitch {plan.grasp.palm_pitch_deg:.1f} deg")
    ax.legend(loc="upper left")
    fig.savefig(args.out, dpi=120)
    print(f"figure written to {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
