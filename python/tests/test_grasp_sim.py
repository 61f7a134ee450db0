"""Tests of the Python package (issue 36): the installed grasp_sim against the CLI of the same
tree.

The CLI is ``$GRASP_SIM_CLI``, else the newest of target/{release,debug}/grasp-sim; without one
the tests that compare with it skip, unless ``GRASP_SIM_REQUIRE_CLI=1`` (CI) makes that a
failure.
"""

import json
import os
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import grasp_sim as gs

ROOT = Path(__file__).resolve().parents[2]
CUP_STL = ROOT / "assets" / "objects" / "cup.stl"


def cli_binary():
    given = os.environ.get("GRASP_SIM_CLI")
    if given:
        return Path(given)
    found = [p for p in (ROOT / "target" / d / "grasp-sim" for d in ("release", "debug")) if p.is_file()]
    if found:
        return max(found, key=lambda p: p.stat().st_mtime)
    if os.environ.get("GRASP_SIM_REQUIRE_CLI") == "1":
        pytest.fail("GRASP_SIM_REQUIRE_CLI=1 but no grasp-sim binary (set GRASP_SIM_CLI or build it)")
    pytest.skip("no grasp-sim binary to compare with (cargo build, or GRASP_SIM_CLI)")


def cli(*args):
    """The CLI's (status, stdout, stderr), run from the repository root."""
    r = subprocess.run([str(cli_binary()), *map(str, args)], cwd=ROOT, capture_output=True, text=True)
    return r.returncode, r.stdout, r.stderr


def without_timings(v):
    """The JSON without wall-clock timings, as scripts/structure_diff.sh compares it."""
    if isinstance(v, dict):
        return {k: without_timings(x) for k, x in v.items() if k not in ("wall_ms", "timings_ms")}
    if isinstance(v, list):
        return [without_timings(x) for x in v]
    return v


def stl_triangles(path):
    """The corners of a binary STL's triangles, (M, 3, 3) float32, read with numpy alone."""
    data = path.read_bytes()
    count = int(np.frombuffer(data, "<u4", 1, 80)[0])
    assert len(data) == 84 + 50 * count, "a binary STL"
    rec = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    return np.frombuffer(data, rec, count, 84)["v"]


@pytest.fixture(scope="module")
def cup():
    # As scenarios/cup.toml has it: the file's frame, 500 kg/m^3, mu 0.3.
    return gs.Object.from_file(CUP_STL, frame="file", density_kg_m3=500.0, friction=0.3)


# As scenarios/cup.toml has it: the thesis's order (every order factor 0).
THESIS_ORDER = dict(sf_centred=0.0, sf_opposed=0.0, sf_spread=0.0, sf_margin=0.0, sf_even=0.0)


@pytest.fixture(scope="module")
def cup_plan(cup):
    return gs.plan(cup, **THESIS_ORDER)


# --- The cup from Python equals the CLI's JSON (timings aside).

def test_run_scenario_gives_exactly_the_cli_json_line(monkeypatch):
    monkeypatch.chdir(ROOT)
    status, out, err = cli("--json", "scenarios/cup.toml")
    assert status == 0, err
    from_cli = json.loads(out)
    from_python = gs.run_scenario("scenarios/cup.toml")
    assert without_timings(from_python) == without_timings(from_cli)
    assert from_python["sim"]["verdict"] == "hold"


def test_plan_and_check_of_the_cup_equal_the_cli(cup, cup_plan):
    status, out, err = cli("--json", "scenarios/cup.toml")
    assert status == 0, err
    from_cli = json.loads(out)
    assert cup_plan.status == "feasible"
    g = cup_plan.grasp
    want = from_cli["plan"]["grasp"]
    assert g.elevation_index == want["elevation_index"]
    assert g.palm_pitch_deg == want["palm_pitch_deg"]
    np.testing.assert_array_equal(
        g.joint_angles_deg, [[f["theta1_deg"], f["theta2_deg"]] for f in want["fingers"]]
    )
    assert g.palm_pose.shape == (4, 4) and g.joint_angles_deg.shape == (3, 2)
    np.testing.assert_allclose(g.palm_pose[:3, 3], want["palm_pose"]["position_mm"])
    np.testing.assert_allclose(g.palm_pose[:3, :3] @ g.palm_pose[:3, :3].T, np.eye(3), atol=1e-9)
    assert g.rules == want["rules"] and list(g.axis) == want["axis"]
    checked = gs.check(cup, cup_plan)
    assert checked.verdict == from_cli["sim"]["verdict"] == "hold"
    assert without_timings(checked.sim) == without_timings(from_cli["sim"])
    assert len(checked.directions) == 1


# --- Any grasp can be checked as given: another candidate, or a pose from elsewhere.

def test_a_grasp_from_a_pose_is_checked_as_given(cup, cup_plan):
    g = cup_plan.grasp
    planned = gs.check(cup, cup_plan)
    # The plan's own grasp, given back as a pose: the same verdict, and a closing shift within
    # half a millimetre of the planner's check of it.
    same = gs.check(cup, gs.Grasp.from_pose(g.palm_pose, g.joint_angles_deg, g.axis_name))
    assert same.sim["grasp_source"] == "given" and planned.sim["grasp_source"] == "planner"
    assert same.verdict == planned.verdict == "hold"
    assert abs(same.closing["shift_mm"] - planned.closing["shift_mm"]) < 0.5
    np.testing.assert_allclose(same.grasp.palm_pose, g.palm_pose)
    # The palm 60 mm back along its own x axis (away from the cup): the fingers close on
    # nothing and the cup drops.
    back = g.palm_pose.copy()
    back[:3, 3] += 60.0 * back[:3, 0]
    assert gs.check(cup, gs.Grasp.from_pose(back, g.joint_angles_deg, g.axis_name)).verdict == "drop"


def test_a_plan_whose_first_closing_leaves_it_is_checked_on_its_own_grasp():
    # The door handle's first candidate closes off its plan, so a run's search goes on to the
    # closings' order; checking the plan checks the plan's grasp all the same.
    handle = gs.Object.from_file(ROOT / "assets" / "real" / "meshes" / "mw_door_handle.stl")
    p = gs.plan(handle)
    c = gs.check(handle, p)
    assert c.grasp.raw["palm_pose"] == p.grasp.raw["palm_pose"]
    assert c.fidelity["as_planned"] is False


def test_a_later_candidate_is_checked_as_given(cup):
    p = gs.plan(cup, candidates=3)
    assert len(p.candidates) == 3
    c = gs.check(cup, p.candidates[2])
    assert c.sim["grasp_source"] == "given" and c.verdict in ("hold", "slip", "drop")
    assert c.grasp is p.candidates[2]


def test_samples_give_the_hold_probability_as_the_cli(cup, cup_plan):
    status, out, err = cli("--json", "--samples", "4", "scenarios/cup.toml")
    assert status == 0, err
    from_cli = json.loads(out)["sim"]["robust"]
    c = gs.check(cup, cup_plan, samples=4)
    assert c.robust is not None and c.robust["samples"] == 4
    assert without_timings(c.robust) == without_timings(from_cli)
    lo, hi = c.robust["interval"]
    assert 0.0 <= lo <= c.hold_probability <= hi <= 1.0
    assert gs.check(cup, cup_plan).robust is None
    with pytest.raises(gs.BadScenarioError, match="samples"):
        gs.check(cup, cup_plan, samples=0)


@pytest.mark.parametrize("pose, angles, message", [
    (np.eye(4) * 2, [[150, 150]] * 3, "is not a rotation"),
    (np.eye(3), [[150, 150]] * 3, "4 × 4"),
    (np.eye(4), [[150, 150]] * 2, "2 fingers' joint angles for a hand of 3 fingers"),
    (np.eye(4), [[150, float("nan")]] * 3, "not a finite number"),
    (np.eye(4), [150, 150, 150], "shape (fingers, 2)"),
])
def test_a_bad_given_grasp_raises(cup, pose, angles, message):
    with pytest.raises(gs.BadInputError, match=message.replace("(", r"\(").replace(")", r"\)")):
        gs.check(cup, gs.Grasp.from_pose(pose, angles))


def test_an_axis_the_planner_did_not_search_raises(cup, cup_plan):
    g = cup_plan.grasp
    with pytest.raises(gs.BadInputError, match='axis "sideways" is not a principal axis'):
        gs.check(cup, gs.Grasp.from_pose(g.palm_pose, g.joint_angles_deg, "sideways"))


def test_a_grasp_on_an_axis_the_search_did_not_reach_is_checked_there(cup, cup_plan):
    # The cup's plan is on its least axis; the same pose about its middle axis is aligned for
    # the check as the planner would align it (gravity then along that frame's -Z).
    g = cup_plan.grasp
    c = gs.check(cup, gs.Grasp.from_pose(g.palm_pose, g.joint_angles_deg, "middle"))
    assert c.verdict in ("hold", "slip", "drop")
    assert c.report["sim"]["grasp_source"] == "given"


def test_check_many_labels_each_grasp_as_the_cli_does(cup):
    p = gs.plan(cup, candidates=40)
    grasps = [p.candidates[0], p.candidates[39]]
    bad = {"palm_pose": np.eye(4).tolist(), "joint_angles_deg": [[150, 150]] * 2}
    records = gs.check_many(cup, [*grasps, bad], samples=2)
    assert len(records) == 3
    for r in records[:2]:
        assert r["samples"] == 2 and 0.0 <= r["hold_probability"] <= 1.0
        assert r["verdict"] in ("hold", "slip", "drop")
        assert np.allclose(np.asarray(r["palm_pose"]), p.candidates[0].palm_pose if r is records[0]
                           else p.candidates[39].palm_pose, atol=1e-6)
    assert "error" in records[2] and "2 fingers' angles" in records[2]["error"]
    with pytest.raises(gs.BadInputError, match="samples"):
        gs.check_many(cup, grasps, samples=0)


# --- Arrays in give the same plan as the file.

def plan_section(p):
    return without_timings(p.report["plan"])


def test_arrays_of_the_file_give_the_same_plan_as_the_file(cup, cup_plan):
    tris = stl_triangles(CUP_STL)
    vertices = tris.reshape(-1, 3).astype(np.float64)
    faces = np.arange(len(vertices)).reshape(-1, 3)
    arrays = gs.Object.from_arrays(vertices, faces, frame="file", density_kg_m3=500.0, friction=0.3)
    np.testing.assert_array_equal(arrays.vertices, cup.vertices)
    np.testing.assert_array_equal(arrays.faces, cup.faces)
    assert plan_section(gs.plan(arrays, **THESIS_ORDER)) == plan_section(cup_plan)


def test_the_loaded_mesh_given_back_as_arrays_plans_the_same(cup, cup_plan):
    again = gs.Object.from_arrays(cup.vertices, cup.faces, frame="file", density_kg_m3=500.0)
    assert plan_section(gs.plan(again, **THESIS_ORDER)) == plan_section(cup_plan)


def test_a_trimesh_is_accepted_where_trimesh_is_installed(cup, cup_plan):
    trimesh = pytest.importorskip("trimesh")
    mesh = trimesh.Trimesh(cup.vertices, cup.faces, process=False)
    obj = gs.Object.from_trimesh(mesh, frame="file", density_kg_m3=500.0)
    assert plan_section(gs.plan(obj, **THESIS_ORDER)) == plan_section(cup_plan)


# --- NaN coordinates and an out-of-range face index raise GraspSimError.

TETRA_V = np.array([[0, 0, 0], [40, 0, 0], [0, 40, 0], [0, 0, 40]], dtype=float)
TETRA_F = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def test_nan_coordinates_raise():
    v = TETRA_V.copy()
    v[2, 1] = np.nan
    with pytest.raises(gs.GraspSimError) as e:
        gs.Object.from_arrays(v, TETRA_F)
    assert isinstance(e.value, gs.BadInputError)
    assert str(e.value) == "<arrays>: triangle 0 has a NaN or infinite coordinate"


def test_an_out_of_range_face_index_raises():
    f = TETRA_F.copy()
    f[3, 1] = 99
    with pytest.raises(gs.BadInputError) as e:
        gs.Object.from_arrays(TETRA_V, f)
    assert str(e.value) == "<arrays>: face 4 refers to vertex 99, but the file has 4 vertices"
    with pytest.raises(gs.BadInputError, match="refers to vertex -1"):
        gs.Object.from_arrays(TETRA_V, -np.ones((1, 3), dtype=np.int32))


@pytest.mark.parametrize(
    "vertices, faces, message",
    [
        (np.zeros((4, 2)), TETRA_F, "must be"),
        (TETRA_V, TETRA_F.astype(float), "integer"),
        (TETRA_V, np.zeros((0, 3), dtype=int), "no triangles"),
    ],
)
def test_other_bad_arrays_raise(vertices, faces, message):
    with pytest.raises(gs.BadInputError, match=message):
        gs.Object.from_arrays(vertices, faces)


def test_a_bad_mesh_file_raises_the_cli_message(tmp_path):
    bad = tmp_path / "bad.obj"
    bad.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(gs.BadInputError) as e:
        gs.Object.from_file(bad)
    status, _, err = cli(bad)
    assert status == 2
    assert err.strip() == f"grasp-sim: error: {e.value}"


def test_a_bad_scenario_raises_the_cli_message(tmp_path):
    s = tmp_path / "typo.toml"
    s.write_text(f'[object]\nmesh = "{CUP_STL}"\n[planner]\nheigh_step_mm = 2.5\n')
    with pytest.raises(gs.BadScenarioError) as e:
        gs.run_scenario(s)
    status, _, err = cli("--json", s)
    assert status == 2
    assert err.strip() == f"grasp-sim: error: {e.value}"
    assert "did you mean `height_step_mm`" in str(e.value)


def test_keyword_parameters_are_validated_as_scenario_keys(cup):
    with pytest.raises(gs.BadScenarioError, match="did you mean `height_step_mm`"):
        gs.plan(cup, heigh_step_mm=2.5)
    with pytest.raises(gs.BadScenarioError, match="sim.duration_s"):
        gs.check(cup, None, duration_s=0.0)
    with pytest.raises(gs.BadScenarioError, match="not a scenario value"):
        gs.plan(cup, sf_c=object())
    with pytest.raises(gs.BadScenarioError, match="sim.override_angles"):
        gs.check(cup, None, override_angles=np.array([[90.0, 90.0]]))


# --- Hands.

def test_hands_load_with_their_parameters_readable(tmp_path):
    thesis = gs.Hand.load("thesis")
    assert thesis.name == "thesis" and thesis.finger_names == ["finger_1", "finger_2", "finger_3"]
    assert thesis.params["fingers"]["gap_mm"] == 25.0
    assert thesis.params["joints"]["theta1_range_deg"] == [45.0, 135.0]
    assert gs.Hand.load("bh8").name == "bh8"
    short = gs.Hand.load(ROOT / "assets" / "hands" / "thesis.toml", {"phalanx_2.length_mm": 18.0})
    assert short.params["phalanx_2"]["length_mm"] == 18.0
    with pytest.raises(gs.BadHandError, match="no such file"):
        gs.Hand.load(tmp_path / "nope.toml")
    with pytest.raises(gs.BadHandError, match="palm.offset_mm"):
        gs.Hand.load("thesis", {"palm.offset_mm": -1.0})


def test_an_ungraspable_object_is_an_outcome_not_an_error():
    thin = gs.Object.from_file(ROOT / "assets" / "objects" / "cylinder_d10.stl")
    p = gs.plan(thin)
    assert p.status == "ungraspable" and p.grasp is None and "too thin" in p.reason
    assert gs.check(thin, None).verdict == "not_run"


# --- A three-object batch reports progress.

def test_a_three_object_batch_reports_progress(tmp_path, monkeypatch):
    monkeypatch.chdir(ROOT)
    inputs = ["scenarios/cylinder_d40.toml", "scenarios/cup.toml", "scenarios/prism.toml"]
    seen = []
    out = tmp_path / "results.jsonl"
    lines = list(gs.batch(inputs, jobs=2, out=out, progress=lambda *a: seen.append(a)))
    assert [(d, t) for d, t, _ in seen] == [(1, 3), (2, 3), (3, 3)]
    assert sorted(m.split(":")[0] for _, _, m in seen) == sorted(inputs)
    assert sorted(r["batch"]["input"] for r in lines) == sorted(inputs)
    assert all(r["expect"]["met"] for r in lines)
    written = [json.loads(x) for x in out.read_text().splitlines()]
    assert [r["batch"]["input"] for r in written] == inputs
    # The same line as the CLI's batch, timings aside.
    status, cli_out, err = cli("batch", "--in-process", *inputs)
    assert status == 0, err
    assert [without_timings(json.loads(x)) for x in cli_out.splitlines()] == [without_timings(r) for r in written]
    # Resumed: every line is kept, nothing runs again.
    again = list(gs.batch(inputs, out=out, resume=True))
    assert [without_timings(r) for r in again] == [without_timings(r) for r in written]


def test_a_bad_batch_input_is_an_error_line_or_raises(tmp_path, monkeypatch):
    bad = tmp_path / "bad.stl"
    bad.write_bytes(b"not a mesh")
    (line,) = gs.batch([bad])
    assert "error" in line and str(bad) in line["error"]
    # A missing input named like one is an error line of its own, as in `grasp-sim batch`
    # (issue 32); a name that is no input at all is refused.
    (line,) = gs.batch([tmp_path / "missing.toml"])
    assert "no such file" in line["error"]
    with pytest.raises(gs.GraspSimError, match="no such file or folder"):
        list(gs.batch([tmp_path / "missing"]))


def test_a_panic_in_the_library_is_an_error_line_not_a_crash(monkeypatch):
    if not gs._native.DEBUG_BUILD:
        pytest.skip("the library's fault hook (GRASP_SIM_TEST_FAULT) is in debug builds only")
    monkeypatch.chdir(ROOT)
    monkeypatch.setenv("GRASP_SIM_TEST_FAULT", "panic:cylinder_d40")
    lines = {r["batch"]["input"]: r for r in gs.batch(["scenarios/cylinder_d40.toml", "scenarios/cup.toml"])}
    assert "panicked: test fault" in lines["scenarios/cylinder_d40.toml"]["error"]
    assert lines["scenarios/cup.toml"]["sim"]["verdict"] == "hold"


# --- Another Python thread makes progress while a check runs (the GIL is released).

def test_another_thread_runs_while_a_check_runs(cup, cup_plan):
    ticks = [0]
    stop = threading.Event()

    def count():
        while not stop.is_set():
            ticks[0] += 1

    t = threading.Thread(target=count)
    t.start()
    try:
        time.sleep(0.05)
        before, t0 = ticks[0], time.perf_counter()
        result = gs.check(cup, cup_plan, gravity="six")
        during, seconds = ticks[0] - before, time.perf_counter() - t0
    finally:
        stop.set()
        t.join()
    assert result.verdict in ("hold", "slip", "drop") and len(result.directions) == 6
    # With the GIL held for the whole check the counter could not move; released, it counts
    # at its usual rate (millions a second) for the check's duration.
    assert seconds > 0.05, f"the check took {seconds:.3f} s: too short to tell"
    assert during > 10_000 * seconds, f"{during} ticks in {seconds:.3f} s"


def test_bad_keyword_values_raise_naming_the_key(cup):
    # Issue 56: candidates=-1 raised a bare OverflowError, inf and NaN a JSON message that
    # named no key, and 10^8 vertices took the interpreter down.
    with pytest.raises(gs.BadScenarioError, match=r"`candidates` must be in 1..=1000, got -1"):
        gs.plan(cup, candidates=-1)
    with pytest.raises(gs.BadScenarioError, match=r"`planner.sf_c` must be a finite number, got nan"):
        gs.plan(cup, sf_c=float("nan"))
    with pytest.raises(gs.BadScenarioError, match=r"`sim.duration_s` must be a finite number, got inf"):
        gs.check(cup, duration_s=float("inf"))
    with pytest.raises(gs.BadScenarioError, match=r"`samples`"):
        gs.check(cup, samples=0)
    big = np.broadcast_to(np.zeros(3), (10**8, 3))  # no memory of its own
    with pytest.raises(gs.BadInputError, match=r"100000000 vertices, more than the"):
        gs.Object.from_arrays(big, np.zeros((1, 3), dtype=np.int64))
