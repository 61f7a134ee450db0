#!/usr/bin/env python3
"""Replay a grasp exported by `grasp-sim --export-mjcf DIR` in MuJoCo, with grasp-sim's protocol.

    python3 scripts/mujoco_replay.py [--six] [--trace] [--libccd] DIR/<scenario> [DIR/<scenario> ...]

Prints one JSON object per scene: the verdict (hold / slip / drop: what gravity did, by the same
hold thresholds as grasp-sim's rapier check), the object's translation and rotation relative to
the palm during the hold, whether it still touches the hand, and the closing's fidelity
(`fidelity`: as planned or not by `max_closing_shift_mm`, `min_on_plan_fraction` and
`max_penetration_mm`, with the figures, as grasp-sim's `sim.fidelity`). Protocol (docs/SIM.md),
read from protocol.json: fingers start at the `open` keyframe; gravity off; joint 1 closes towards its target (planned
bend plus squeeze) while joint 2 is held open; when the hand and the object have stopped
(`close_until_stalled`), or at the latest halfway through the closing time, joint 1 locks where
it stopped (a TorqueSwitch) and joint 2 closes, again until they stop; with `reseat` (the
default) each locked joint 1 whose phalanx 1 is off the object moves on until it touches, until
no joint 1 moves and the object has stopped; then gravity on for the hold (its
whole length: the replay is the full-length protocol).
`--six`: the six gravity directions of `[sim] gravity = "six"`, each held from one closing.
Perturbed samples (`[sim] samples`, issue 34) are exported as scenes of their own,
DIR/<scenario>/samples/<k>/; scripts/compare_engines.py --robust replays them.
`--trace`: the closing on stderr, to hold against grasp-sim's `sim.closing` (issue 33): when
each body first touches the object; every 10 ms the object's shift from its start relative to
the palm, each joint's bend minus its plan and the bodies touching the object; at the end of
each phase, every contact with the object (point in the palm frame [mm], normal, normal and
tangential force, depth). The result is the same with or without it.
`--libccd`: MuJoCo's older convex collision (libccd) instead of its native one, a change to
the collision algorithm alone: the verdicts it changes are those MuJoCo itself cannot decide
(docs/studies/2026-12-05-engine-chaos.md).
Needs `pip install mujoco`.
"""
import json
import math
import pathlib
import sys
import time

import mujoco
import numpy as np


def quat_angle_deg(q1, q2):
    d = abs(float(np.dot(q1, q2)))
    return math.degrees(2.0 * math.acos(min(1.0, d)))


def relative_pose(m, d, palm, obj):
    """The object's body frame in the palm's frame: (position in mm, rotation matrix)."""
    rp = d.xmat[palm].reshape(3, 3)
    ro = d.xmat[obj].reshape(3, 3)
    p = rp.T @ (d.xpos[obj] - d.xpos[palm])
    return p * 1000.0, rp.T @ ro


SIX = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]


def touching_bodies(m, d, obj):
    """The names of the bodies touching `obj` now."""
    out = set()
    for c in d.contact[: d.ncon]:
        b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
        if obj in (b1, b2):
            out.add(m.body(b2 if b1 == obj else b1).name)
    return out


def trace_line(m, d, stamp, p0, palm, obj, planned, n, contacts=False):
    """One `--trace` line on stderr: time, the object's shift from `p0` [mm], each joint's bend
    minus its plan [deg], the bodies touching the object; with `contacts`, one line per contact."""
    pc, _ = relative_pose(m, d, palm, obj)
    bends = [float(d.qpos[m.jnt_qposadr[m.actuator_trnid[a, 0]]]) for a in range(2 * n)]
    err = " ".join(f"{math.degrees(b - p):+.1f}" for b, p in zip(bends, planned))
    touching = set()
    lines = []
    rp = d.xmat[palm].reshape(3, 3)
    for i, c in enumerate(d.contact[: d.ncon]):
        b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
        if obj not in (b1, b2):
            continue
        other = b2 if b1 == obj else b1
        touching.add(m.body(other).name)
        if contacts:
            f = np.zeros(6)
            mujoco.mj_contactForce(m, d, i, f)
            normal = rp.T @ c.frame[:3] * (1.0 if b1 == obj else -1.0)
            at = rp.T @ (c.pos - d.xpos[palm]) * 1000.0
            lines.append(f"    {m.body(other).name:20s} at {np.round(at, 1)} mm, "
                         f"normal (object to hand) {np.round(normal, 2)}, {f[0]:.2f} N normal, "
                         f"{math.hypot(f[1], f[2]):.2f} N tangential, "
                         f"depth {-c.dist * 1000.0:.3f} mm")
    d_mm = pc - p0
    print(f"{stamp}: shift {np.linalg.norm(d_mm):.2f} mm {np.round(d_mm, 2)}, "
          f"bend - plan [deg] {err}, touching {sorted(touching)}", file=sys.stderr)
    for line in lines:
        print(line, file=sys.stderr)


def replay(scene_dir, directions=None, trace=False, libccd=False):
    """The replay of one exported scene. `directions`: None, the scene's gravity (the check as
    it has always been replayed); or a list of unit vectors (aligned object frame, as `[sim]
    gravity = "six"` gives them, e.g. `SIX`): the closing runs once and each direction holds
    from a copy of the closed state, as grasp-sim's `fast` protocol does; the result then has
    `directions` (one verdict each) and the worst verdict. `trace`: the closing on stderr
    (`--trace`). `libccd`: MuJoCo's libccd collision instead of its native one (`--libccd`)."""
    scene_dir = pathlib.Path(scene_dir)
    proto = json.loads((scene_dir / "protocol.json").read_text())
    m = mujoco.MjModel.from_xml_path(str(scene_dir / "scene.xml"))
    if libccd:
        if not hasattr(mujoco.mjtDisableBit, "mjDSBL_NATIVECCD"):
            sys.exit(f"--libccd: MuJoCo {mujoco.__version__} has no native collision to turn off")
        m.opt.disableflags |= mujoco.mjtDisableBit.mjDSBL_NATIVECCD
    d = mujoco.MjData(m)
    mujoco.mj_resetDataKeyframe(m, d, m.key("open").id)
    n = len(proto["fingers"])
    target = proto["target_bend_rad"]
    opened = proto["open_bend_rad"]
    for k in range(n):
        d.ctrl[2 * k] = target[2 * k]
        d.ctrl[2 * k + 1] = opened[2 * k + 1]
    gravity = m.opt.gravity.copy()
    m.opt.gravity[:] = 0.0
    dt = m.opt.timestep
    close_steps = round(proto["close_duration_s"] / dt)
    hold_steps = round(proto["duration_s"] / dt)
    kp = proto["motor_stiffness_nm_per_rad"]
    lock = proto["joint1_lock_torque_nm"]
    palm = m.body("palm").id
    obj = m.body("object").id
    # The simulation loop alone is timed (`wall_ms`): no Python start-up, no model loading.
    t0 = time.perf_counter()
    # Joint 1 closes for at most half the closing time, then joint 2 for the rest; with
    # `close_until_stalled` each phase ends once every finger joint and the object have stayed
    # slower than the `stall` speeds for its window (the same rule as grasp-sim's).
    stall = proto["stall"] if proto.get("close_until_stalled") else None
    hinge_dofs = [m.jnt_dofadr[m.actuator_trnid[a, 0]] for a in range(2 * n)]
    od = m.jnt_dofadr[m.body_jntadr[obj]]

    def quiet(joints=True):
        joint = max(abs(float(d.qvel[i])) for i in hinge_dofs) if joints else 0.0
        v = float(np.linalg.norm(d.qvel[od:od + 3])) * 1000.0
        w = float(np.linalg.norm(d.qvel[od + 3:od + 6]))
        return joint < stall["joint_rad_s"] and v < stall["object_mm_s"] and w < stall["object_rad_s"]

    # Body poses of the keyframe (mj_resetDataKeyframe sets qpos only): positions, nothing else.
    mujoco.mj_kinematics(m, d)
    p0, r0 = relative_pose(m, d, palm, obj)
    # `approach = "together"` (issue 33): a finger that touches the object stops there until
    # every finger has touched, or the hand has stopped, then all squeeze (as grasp-sim's).
    waiting = proto.get("approach", "squeeze") == "together"
    held = [False] * n
    finger_bodies = [{m.body(f"{f}_phalanx_{j}").id for j in (1, 2)} for f in proto["fingers"]]
    joint1_qpos = [m.jnt_qposadr[m.actuator_trnid[2 * k, 0]] for k in range(n)]

    def touching_fingers():
        out = [False] * n
        for c in d.contact[: d.ncon]:
            b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
            other = b2 if b1 == obj else b1 if b2 == obj else None
            for k in range(n):
                if other in finger_bodies[k]:
                    out[k] = True
        return out

    def release():
        for k in range(n):
            if held[k]:
                d.ctrl[2 * k] = target[2 * k]
            held[k] = False

    # `approach = "timed"` (issue 33): every joint 1 target moves from its open bend to its
    # planned bend in the same `ramp_s`, then on to the squeeze target (as grasp-sim's).
    planned = proto.get("planned_bend_rad")
    ramp_steps = max(1, round(proto.get("ramp_s", 0.1) / dt))
    ramp = 0 if proto.get("approach") == "timed" else None
    if ramp is not None:
        for k in range(n):
            d.ctrl[2 * k] = opened[2 * k]
    # `reseat` (issue 33): after joint 2, each locked joint 1 whose phalanx 1 does not touch the
    # object moves on at `reseat_rad_s` until it touches or reaches its squeeze target.
    reseat_step = proto.get("reseat_rad_s", 0.0) * dt
    phalanx1 = [m.body(f"{f}_phalanx_1").id for f in proto["fingers"]]

    def phalanx1_touching():
        out = [False] * n
        for c in d.contact[: d.ncon]:
            b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
            other = b2 if b1 == obj else b1 if b2 == obj else None
            for k in range(n):
                out[k] = out[k] or other == phalanx1[k]
        return out

    # `reseat_only_lifted`: only a joint 1 whose phalanx 1 touched the object earlier in the
    # closing moves on (as grasp-sim's). Every export writes it; a protocol.json without it was
    # written before the key existed, when every joint 1 was reseated.
    only_lifted = bool(proto.get("reseat_only_lifted", False))
    p1_touched = [False] * n

    def lock_joint1():
        for k in range(n):
            a = 2 * k
            joint = m.actuator_trnid[a, 0]
            d.ctrl[a] = d.qpos[m.jnt_qposadr[joint]]
            m.actuator_gainprm[a, 0] = 10.0 * kp
            m.actuator_biasprm[a, 1] = -10.0 * kp
            m.actuator_forcerange[a] = [-lock, lock]

    first_touch = set()
    phases = [close_steps // 2, close_steps - close_steps // 2]
    if proto.get("reseat"):
        phases.append(close_steps // 2)
    closed = 0
    for phase, max_steps in enumerate(phases):
        if phase == 2:
            # Each joint 1 moves on from where it is now, not from where it was locked (joint 2's
            # squeeze may have moved it): as grasp-sim's.
            reseat_at = [float(d.qpos[joint1_qpos[k]]) for k in range(n)]
        if phase == 1:
            if waiting:
                release()
                waiting = False
            if ramp is not None:
                ramp = None
                for k in range(n):
                    d.ctrl[2 * k] = target[2 * k]
            lock_joint1()
            for k in range(n):
                d.ctrl[2 * k + 1] = target[2 * k + 1]
        quiet_steps = 0
        for _ in range(max_steps):
            moving = False
            if phase == 2:
                for k, t1 in enumerate(phalanx1_touching()):
                    lifted = not only_lifted or p1_touched[k]
                    if not t1 and lifted and reseat_at[k] < target[2 * k]:
                        reseat_at[k] = min(reseat_at[k] + reseat_step, target[2 * k])
                        d.ctrl[2 * k] = reseat_at[k]
                        moving = True
            if ramp is not None and ramp < ramp_steps:
                ramp += 1
                s = ramp / ramp_steps
                for k in range(n):
                    d.ctrl[2 * k] = target[2 * k] if ramp == ramp_steps else \
                        opened[2 * k] + (planned[2 * k] - opened[2 * k]) * s
            mujoco.mj_step(m, d)
            closed += 1
            if only_lifted:
                p1_touched = [a or b for a, b in zip(p1_touched, phalanx1_touching())]
            if trace:
                for name in sorted(touching_bodies(m, d, obj) - first_touch):
                    first_touch.add(name)
                    print(f"t={closed * dt:.4f} s: {name} first touches the object",
                          file=sys.stderr)
            if trace and closed % round(0.01 / dt) == 0:
                trace_line(m, d, f"t={closed * dt:.3f} s", p0, palm, obj, planned or target, n)
            if ramp is not None and ramp < ramp_steps:
                quiet_steps = 0
                continue
            if waiting:
                for k, t in enumerate(touching_fingers()):
                    if t and not held[k]:
                        d.ctrl[2 * k] = d.qpos[joint1_qpos[k]]
                        held[k] = True
                if all(held):
                    release()
                    waiting = False
                    quiet_steps = 0
            if stall is None:
                continue
            # The reseat ends on the object's speeds alone (as grasp-sim's: a seated finger's
            # joint 2 chatters at about the joint threshold).
            if quiet(joints=phase != 2) and not moving:
                quiet_steps += 1
                if quiet_steps * dt >= stall["window_s"]:
                    if waiting:
                        release()
                        waiting = False
                        quiet_steps = 0
                        continue
                    break
            else:
                quiet_steps = 0
        if trace:
            trace_line(m, d, f"end of phase {phase} (t={closed * dt:.3f} s)", p0, palm, obj,
                       planned or target, n, contacts=True)
    pc, rc = relative_pose(m, d, palm, obj)
    # What the closing did (issues 33 and 55): a closing that pushed the object farther than
    # `max_closing_shift_mm` did not keep the planned grasp, as in grasp-sim's check.
    closing_shift = float(np.linalg.norm(pc - p0))
    q0c = np.zeros(4)
    qcc = np.zeros(4)
    mujoco.mju_mat2Quat(q0c, r0.flatten())
    mujoco.mju_mat2Quat(qcc, rc.flatten())
    closing_turn = quat_angle_deg(q0c, qcc)
    max_shift = proto.get("max_closing_shift_mm", math.inf)
    pushed = closing_shift > max_shift
    # Nor is a hold that left fewer phalanges on the object within 5 deg of their planned bend
    # than `min_on_plan_fraction` asks (as grasp-sim's).
    on_plan = on_plan_count(m, d, proto, obj, planned) if planned else None
    fraction = proto.get("min_on_plan_fraction", 0.0)
    off_plan = on_plan is not None and on_plan < math.ceil(fraction * 2 * n - 1e-9)
    # Nor is one that left a hand body deeper in the object than `max_penetration_mm`.
    depth = penetration_mm(m, d, obj, proto["fingers"])
    penetrated = depth > proto.get("max_penetration_mm", math.inf)
    reasons = [r for r, on in (("pushed", pushed), ("off_plan", off_plan),
                               ("penetrated", penetrated)) if on]
    errors = closing_errors_deg(m, d, planned, n) if planned else []
    fidelity = {
        "as_planned": not reasons, "shift_mm": closing_shift, "turn_deg": closing_turn,
        "phalanges_on_plan": on_plan, "phalanges": 2 * n,
        "worst_joint_error_deg": max(errors, key=abs) if errors else 0.0,
        "penetration_mm": depth, "reasons": reasons,
    }
    closing = {
        "closed": closed, "t0": t0, "pc": pc, "rc": rc, "pushed": pushed,
        "closing_shift_mm": closing_shift, "closing_turn_deg": closing_turn,
        "closing_off_plan": off_plan, "phalanges_on_plan": on_plan, "fidelity": fidelity,
    }
    if directions is None:
        return hold(m, d, proto, gravity, hold_steps, closing)
    g = float(np.linalg.norm(gravity))
    closed_state = mujoco.MjData(m)
    mujoco.mj_copyData(closed_state, m, d)
    runs = []
    for u in directions:
        di = mujoco.MjData(m)
        mujoco.mj_copyData(di, m, closed_state)
        r = hold(m, di, proto, g * np.asarray(u, dtype=float), hold_steps, closing)
        r["gravity"] = list(u)
        runs.append(r)
    order = {"hold": 0, "slip": 1, "drop": 2}
    worst = max(runs, key=lambda r: (order[r["verdict"]], r["translation_mm"]))
    out = dict(worst)
    out.pop("gravity")
    out["directions"] = [{"gravity": r["gravity"], "verdict": r["verdict"],
                          "as_planned": r["fidelity"]["as_planned"],
                          "translation_mm": r["translation_mm"], "rotation_deg": r["rotation_deg"]}
                         for r in runs]
    out["wall_ms"] = (time.perf_counter() - t0) * 1000.0
    out["steps"] = closed + sum(r["steps"] - closed for r in runs)
    return out


def hold(m, d, proto, gravity, hold_steps, closing):
    """Gravity on along `gravity` (m/s²) for the whole hold from the closed state in `d`."""
    closed, t0, pc, rc, pushed = (closing[k] for k in ("closed", "t0", "pc", "rc", "pushed"))
    palm = m.body("palm").id
    obj = m.body("object").id
    dt = m.opt.timestep
    m.opt.gravity[:] = gravity
    for _ in range(hold_steps):
        mujoco.mj_step(m, d)
    wall_ms = (time.perf_counter() - t0) * 1000.0
    pe, re = relative_pose(m, d, palm, obj)
    translation = float(np.linalg.norm(pe - pc))
    qc = np.zeros(4)
    qe = np.zeros(4)
    mujoco.mju_mat2Quat(qc, rc.flatten())
    mujoco.mju_mat2Quat(qe, re.flatten())
    full_rotation = quat_angle_deg(qc, qe)
    tilt = math.degrees(math.acos(max(-1.0, min(1.0, float(rc[:, 2] @ re[:, 2])))))
    rotation = tilt if proto["is_revolution"] else full_rotation
    hand_bodies = {palm} | {m.body(f"{f}_phalanx_{j}").id for f in proto["fingers"] for j in (1, 2)}
    in_contact = False
    for c in d.contact[: d.ncon]:
        b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
        if (b1 == obj and b2 in hand_bodies) or (b2 == obj and b1 in hand_bodies):
            in_contact = True
    # The verdict is what gravity did (issue 55); the fidelity says whether it was the plan.
    if translation <= proto["hold_translation_mm"] and rotation <= proto["hold_rotation_deg"]:
        verdict = "hold"
    elif in_contact:
        verdict = "slip"
    else:
        verdict = "drop"
    return {
        "scenario": proto["scenario"],
        "engine": f"mujoco {mujoco.__version__}",
        "verdict": verdict,
        "translation_mm": translation,
        "rotation_deg": rotation,
        "full_rotation_deg": full_rotation,
        "in_contact": in_contact,
        "wall_ms": wall_ms,
        "steps": closed + hold_steps,
        "closed_at_s": closed * dt,
        "closing_shift_mm": closing["closing_shift_mm"],
        "closing_turn_deg": closing["closing_turn_deg"],
        "closing_pushed": pushed,
        "closing_off_plan": closing["closing_off_plan"],
        "phalanges_on_plan": closing["phalanges_on_plan"],
        "fidelity": closing["fidelity"],
    }


def penetration_mm(m, d, obj, fingers):
    """The deepest contact between the object and the hand now [mm] (0 when none)."""
    hand = {m.body("palm").id} | {m.body(f"{f}_phalanx_{j}").id for f in fingers for j in (1, 2)}
    depth = 0.0
    for c in d.contact[: d.ncon]:
        b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
        if (b1 == obj and b2 in hand) or (b2 == obj and b1 in hand):
            depth = max(depth, -float(c.dist) * 1000.0)
    return depth


def closing_errors_deg(m, d, planned, n):
    """Each joint's bend minus its planned bend now [deg], in actuator order."""
    return [math.degrees(float(d.qpos[m.jnt_qposadr[m.actuator_trnid[a, 0]]]) - planned[a])
            for a in range(2 * n)]


def on_plan_count(m, d, proto, obj, planned):
    """Phalanges touching the object with their joint within 5 deg of the planned bend."""
    touching = set()
    for c in d.contact[: d.ncon]:
        b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
        if b1 == obj:
            touching.add(b2)
        elif b2 == obj:
            touching.add(b1)
    count = 0
    for k, f in enumerate(proto["fingers"]):
        for j in (0, 1):
            a = 2 * k + j
            bend = float(d.qpos[m.jnt_qposadr[m.actuator_trnid[a, 0]]])
            if (m.body(f"{f}_phalanx_{j + 1}").id in touching
                    and abs(bend - planned[a]) <= math.radians(5.0)):
                count += 1
    return count


def main(argv):
    if len(argv) < 2:
        print(__doc__, file=sys.stderr)
        return 2
    six = "--six" in argv
    trace = "--trace" in argv
    libccd = "--libccd" in argv
    for scene_dir in [a for a in argv[1:] if a not in ("--six", "--trace", "--libccd")]:
        print(json.dumps(replay(scene_dir, SIX if six else None, trace, libccd)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
