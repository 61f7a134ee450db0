#!/usr/bin/env python3
"""Compare the planner's first N candidates of every object across the frames its mesh was written in.

    GRASP_SIM_FRAMES_NO_SIM=1 GRASP_SIM_FRAMES_DUMP=out/fd \\
        cargo test --release --test it frames::every -- --ignored      # writes NAME_SHIFT.stl
    python3 scripts/frames_candidates.py target/release/grasp-sim out/fd [N]

The frame test (tests/it/frames.rs) compares the grasp a run reports; with the physics check a
run may go on to later candidates when the earlier ones fail, so their order matters too
(issue 30, docs/FRAMES.md). For every dumped mesh this plans with `--no-sim --candidates N`
(default 8, bundled thesis hand, defaults) and compares each frame's list against the file's
own frame (shift 0): the same axis, elevation index and approach angle at every rank, and the
palm within 0.5 mm in the aligned frame. Prints each object that differs, with the rank of
the first difference, and the count. Two planner runs at a time.
"""

import collections
import json
import os
import pathlib
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor


def candidates(binary, path, n):
    p = subprocess.run([binary, "--no-sim", "--candidates", str(n), "--json", str(path)],
                       capture_output=True, text=True)
    lines = p.stdout.splitlines()
    if not lines:
        return [("error: " + (p.stderr.strip().splitlines() or ["no output"])[-1], None)]
    plan = json.loads(lines[0]).get("plan") or {}
    return [("%s #%d @%.0f" % (g["axis_name"], g["elevation_index"], g["approach_angle_deg"]),
             g["palm_pose_aligned"]["position_mm"]) for g in plan.get("grasps") or []]


def first_difference(own, other):
    for k in range(max(len(own), len(other))):
        if k >= len(own) or k >= len(other) or own[k][0] != other[k][0]:
            return k
        if own[k][1] and other[k][1] and max(abs(a - b) for a, b in zip(own[k][1], other[k][1])) > 0.5:
            return k
    return None


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    binary, folder = sys.argv[1], pathlib.Path(sys.argv[2])
    n = int(sys.argv[3]) if len(sys.argv) > 3 else 8
    files = sorted(folder.glob("*.stl"))
    objects = collections.defaultdict(dict)
    with ThreadPoolExecutor(2) as ex:
        for f, c in zip(files, ex.map(lambda f: candidates(binary, f, n), files)):
            m = re.match(r"(.*)_(-?\d+)\.stl$", f.name)
            if m:
                objects[m.group(1)][int(m.group(2))] = c
    differ = 0
    for name, frames in sorted(objects.items()):
        own = frames.get(0)
        if own is None:
            continue
        diffs = [(s, k) for s, c in sorted(frames.items()) if s != 0
                 for k in [first_difference(own, c)] if k is not None]
        if diffs:
            differ += 1
            print(f"{name} own: " + ", ".join(x[0] for x in own))
            for s, k in diffs:
                print(f"    frame {s}: from rank {k + 1}: " + ", ".join(x[0] for x in frames[s]))
    print(f"{differ} of {len(objects)} objects differ in their first {n} candidates")


if __name__ == "__main__":
    main()
