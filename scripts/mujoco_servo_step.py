#!/usr/bin/env python3
"""Does MuJoCo's step resolve a finger servo? The thesis hand's phalanx 2 alone on its hinge.

    python3 scripts/mujoco_servo_step.py

The exported scene's phalanx 2 (a 14 x 20 x 14 mm box, density 1000, 5.9e-7 kg m^2 about its
joint) on a position servo as the MJCF export writes it (kp 20 N m/rad, kv 0.2 N m s/rad,
`forcerange` the finger's torque cap, 0.5 or 1 N m), commanded 0.4 rad from rest, gravity and
contacts off. The motor law is tau = clamp(kp e - kv w, -cap, cap); its reference is MuJoCo's
`Euler` integrator at 1 us, where the servo's damping is integrated explicitly and the cap
holds exactly. Printed per step and integrator: the joint's angle (degrees) after 1, 2, 4, 8
and 12 ms, and the largest difference from the reference. Under `implicitfast` (the export's
integrator), where the cap binds, the velocity alternates from step to step unless the step is
small against the servo's natural frequency, sqrt(kp / I) = 5,800 rad/s
(docs/studies/2026-12-06-mujoco-timestep.md).
Needs `pip install mujoco`.
"""
import sys

import mujoco
import numpy as np

XML = """<mujoco><option timestep="{dt}" integrator="{integrator}" gravity="0 0 0"/>
<worldbody><body><joint name="j" type="hinge" axis="0 0 1"/>
<geom type="box" size="0.007 0.010 0.007" pos="0 0.010 0" density="1000" contype="0" conaffinity="0"/>
</body></worldbody>
<actuator><position joint="j" kp="20" kv="0.2" forcerange="-{cap} {cap}"/></actuator></mujoco>"""

TIMES_MS = (1, 2, 4, 8, 12)


def swing(dt, integrator, cap):
    """The joint's angle (degrees) at each of TIMES_MS."""
    m = mujoco.MjModel.from_xml_string(XML.format(dt=dt, integrator=integrator, cap=cap))
    d = mujoco.MjData(m)
    d.ctrl[0] = 0.4
    out, k = [], 0
    for t_ms in TIMES_MS:
        while (k + 1) * dt <= t_ms * 1e-3 + dt / 2:
            mujoco.mj_step(m, d)
            k += 1
        out.append(float(np.degrees(d.qpos[0])))
    return out


def main():
    if len(sys.argv) > 1:
        sys.exit(__doc__)
    print("| cap [N m] | integrator, step | angle at " + ", ".join(f"{t}" for t in TIMES_MS)
          + " ms [deg] | largest difference [deg] |")
    print("|---|---|---|---|")
    for cap in (0.5, 1.0):
        ref = swing(1e-6, "Euler", cap)
        print(f"| {cap} | Euler, 0.001 ms (the reference) | "
              + ", ".join(f"{a:.1f}" for a in ref) + " | |")
        for dt in (2e-4, 1e-4, 5e-5, 2.5e-5, 1.25e-5):
            a = swing(dt, "implicitfast", cap)
            worst = max(abs(x - y) for x, y in zip(a, ref))
            print(f"| {cap} | implicitfast, {dt * 1e3:g} ms | "
                  + ", ".join(f"{x:.1f}" for x in a) + f" | {worst:.1f} |")


if __name__ == "__main__":
    main()
