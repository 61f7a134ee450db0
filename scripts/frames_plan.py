#!/usr/bin/env python3
"""Does each mesh plan alike written in five random rigid frames (issue 30, on any folder)?

    python3 scripts/frames_plan.py [--units U] [--bin PATH] [--keep DIR] MESH...

The test `frames::every_real_object_plans_alike_in_five_random_frames` does this for the
real-object set; this script does it for meshes of your own (STL or OBJ). Each mesh is written
as a binary STL in single precision as it is and in five random rigid frames (seed 30: a
uniformly random rotation and a translation of up to 200 mm, or 0.2 in `--units m`), each
planned with `grasp-sim MESH --no-sim --json`, and the reported grasp compared with the one as
written in the aligned frame, as the test compares them: the palm within 0.5 mm and 0.5 degrees,
every joint angle within 0.5 degrees, the same status. Prints one line per mesh (`OK`, or each
frame that differs) and the count; exits 1 if a mesh differs or cannot be read. Needs numpy;
`--bin` defaults to target/release/grasp-sim.
"""
import argparse
import json
import math
import os
import random
import subprocess
import sys
import tempfile

import numpy as np

from gen_dataset import random_rotation, write_binary_stl
from squeeze_study import load_obj, load_stl


def plan(binary, path, units):
    r = subprocess.run(
        [binary, path, "--no-sim", "--json", "--units", units], capture_output=True, text=True
    )
    try:
        return json.loads(r.stdout)
    except json.JSONDecodeError:
        return None


def differences(a, b):
    if a is None or b is None:
        return ["no JSON (see grasp-sim's message)"]
    pa, pb = a["plan"], b["plan"]
    if pa["status"] != pb["status"]:
        return [f"status {pa['status']} / {pb['status']}"]
    g, h = pa.get("grasp"), pb.get("grasp")
    if not g or not h:
        return []
    out = []
    p, q = g["palm_pose_aligned"], h["palm_pose_aligned"]
    apart = float(np.linalg.norm(np.subtract(p["position_mm"], q["position_mm"])))
    dot = abs(sum(x * y for x, y in zip(p["quaternion_wxyz"], q["quaternion_wxyz"])))
    angle = math.degrees(2 * math.acos(min(1.0, dot)))
    if apart > 0.5 or angle > 0.5:
        name = lambda x: f"{x['axis_name']} #{x['elevation_index']} {x['approach_angle_deg']:g} deg"
        out.append(f"palm {apart:.2f} mm, {angle:.1f} deg apart ({name(g)} / {name(h)})")
    for f, e in zip(g["fingers"], h["fingers"]):
        d = max(abs(f["theta1_deg"] - e["theta1_deg"]), abs(f["theta2_deg"] - e["theta2_deg"]))
        if d > 0.5:
            out.append(f"{f['name']}: joint angles {d:.2f} deg apart")
    return out


def main(argv):
    ap = argparse.ArgumentParser(
        description="Does each mesh plan alike in five random rigid frames? (see the module docs)"
    )
    ap.add_argument("--units", default="mm", help="the meshes' length unit, as grasp-sim --units")
    ap.add_argument("--bin", default="target/release/grasp-sim", help="the grasp-sim binary")
    ap.add_argument("--keep", help="keep the written STLs in this folder")
    ap.add_argument("meshes", nargs="+", metavar="MESH", help="STL or OBJ files")
    args = ap.parse_args(argv)
    units, binary, keep, meshes = args.units, args.bin, args.keep, args.meshes
    rng = random.Random(30)
    reach = 0.2 if units == "m" else 200.0
    frames = [
        (np.array(random_rotation(rng)), np.array([rng.uniform(-reach, reach) for _ in range(3)]))
        for _ in range(5)
    ]
    folder = keep or tempfile.mkdtemp()
    os.makedirs(folder, exist_ok=True)
    differing = unread = 0
    for path in meshes:
        try:
            tri = load_stl(path) if path.lower().endswith(".stl") else load_obj(path)
        except (OSError, ValueError) as e:
            print(f"{path}: not read: {e}", flush=True)
            unread += 1
            continue
        name = os.path.splitext(os.path.basename(path))[0]
        written = os.path.join(folder, f"{name}_0.stl")
        write_binary_stl(written, tri, name)
        reference = plan(binary, written, units)
        lines = []
        for k, (r, t) in enumerate(frames, 1):
            moved = os.path.join(folder, f"{name}_{k}.stl")
            write_binary_stl(moved, tri @ r.T + t, name)
            d = differences(reference, plan(binary, moved, units))
            if d:
                lines.append(f"  frame {k}: " + "; ".join(d))
        differing += bool(lines)
        print(name, "OK" if not lines else "\n" + "\n".join(lines), flush=True)
    print(f"{differing} of {len(meshes)} meshes plan differently in some frame"
          + (f"; {unread} not read" if unread else ""))
    return 1 if differing or unread else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
