# Writes bh8.urdf, bh8.xml, sdh2.urdf and sdh2.xml (issue 37); run from assets/hands/: python3 gen_hand_files.py
import math
# (name, fingers, palm) in metres; each finger: base xyz, base yaw (finger points outward along
# the base frame's x), spread joint or None, l1, l2, tip bend (deg), ranges (rad), box (w, t).
def urdf(name, header, palm_geom, fingers, couplings):
    s = ['<?xml version="1.0"?>', header, f'<robot name="{name}">']
    s.append('  <link name="palm">' + palm_geom + '</link>')
    for f in fingers:
        n = f['name']; base = f['base']; yaw = f['yaw']
        parent = 'palm'
        if f.get('spread'):
            s.append(f'  <link name="{n}_knuckle"><collision><origin xyz="0 0 -0.005"/><geometry><cylinder radius="0.008" length="0.01"/></geometry></collision></link>')
            s.append(f'  <joint name="{n}_spread" type="revolute"><parent link="palm"/><child link="{n}_knuckle"/>'
                     f'<origin xyz="{base[0]} {base[1]} {base[2]}" rpy="0 0 {yaw}"/><axis xyz="0 0 {f["spread_axis"]}"/>'
                     f'<limit lower="0" upper="3.1416" effort="1" velocity="1"/>'
                     + (f'<mimic joint="{f["spread_mimic"]}" multiplier="1"/>' if f.get('spread_mimic') else '') + '</joint>')
            parent = f'{n}_knuckle'; o = (f['knuckle'], 0, 0); rpy = f'0 {f.get("pitch", 0.0):.9f} 0'
        else:
            o = (base[0] + f['knuckle'] * math.cos(yaw), base[1] + f['knuckle'] * math.sin(yaw), base[2]); rpy = f'0 {f.get("pitch", 0.0):.9f} {yaw:.9f}'
        w, t = f['box']; l1, l2 = f['l1'], f['l2']; b = math.radians(f['bend'])
        s.append(f'  <link name="{n}_link_1"><collision><origin xyz="{l1/2} 0 0"/><geometry><box size="{l1} {w} {t}"/></geometry></collision></link>')
        cx, cz = l2 / 2 * math.cos(b), l2 / 2 * math.sin(b)
        s.append(f'  <link name="{n}_link_2"><collision><origin xyz="{cx:.6f} 0 {cz:.6f}" rpy="0 {-b:.6f} 0"/><geometry><box size="{l2} {w} {t}"/></geometry></collision></link>')
        (lo1, hi1), (lo2, hi2) = f['r1'], f['r2']
        s.append(f'  <joint name="{n}_joint_1" type="revolute"><parent link="{parent}"/><child link="{n}_link_1"/>'
                 f'<origin xyz="{o[0]:.6f} {o[1]:.6f} {o[2]}" rpy="{rpy}"/><axis xyz="0 -1 0"/><limit lower="{lo1:.6f}" upper="{hi1:.6f}" effort="1" velocity="1"/></joint>')
        mimic = f'<mimic joint="{n}_joint_1" multiplier="{f["mimic"]}"/>' if f.get('mimic') else ''
        s.append(f'  <joint name="{n}_joint_2" type="revolute"><parent link="{n}_link_1"/><child link="{n}_link_2"/>'
                 f'<origin xyz="{l1} 0 0"/><axis xyz="0 -1 0"/><limit lower="{lo2:.6f}" upper="{hi2:.6f}" effort="1" velocity="1"/>{mimic}</joint>')
    s.append('</robot>')
    return '\n'.join(s) + '\n'

def qz(a): return (math.cos(a/2), 0, 0, math.sin(a/2))
def qy(a): return (math.cos(a/2), 0, math.sin(a/2), 0)
def qmul(a, b):
    w1,x1,y1,z1 = a; w2,x2,y2,z2 = b
    return (w1*w2-x1*x2-y1*y2-z1*z2, w1*x2+x1*w2+y1*z2-z1*y2, w1*y2-x1*z2+y1*w2+z1*x2, w1*z2+x1*y2-y1*x2+z1*w2)
def qstr(q): return ' '.join(f'{v:.9f}' for v in q)
def quat_z(yaw):
    return f'{math.cos(yaw/2):.9f} 0 0 {math.sin(yaw/2):.9f}'
def quat_y(a):
    return f'{math.cos(a/2):.9f} 0 {math.sin(a/2):.9f} 0'

def mjcf(name, header, palm_geom, fingers):
    s = [header, f'<mujoco model="{name}">', '  <compiler angle="radian"/>', '  <worldbody>',
         '    <body name="palm">', '      ' + palm_geom]
    eq = []
    for f in fingers:
        n = f['name']; base = f['base']; yaw = f['yaw']; ind = '      '
        w, t = f['box']; l1, l2 = f['l1'], f['l2']; b = math.radians(f['bend'])
        (lo1, hi1), (lo2, hi2) = f['r1'], f['r2']
        close = []
        if f.get('spread'):
            s.append(f'{ind}<body name="{n}_knuckle" pos="{base[0]} {base[1]} {base[2]}" quat="{quat_z(yaw)}">')
            s.append(f'{ind}  <joint name="{n}_spread" axis="0 0 {f["spread_axis"]}" range="0 3.1416"/>')
            s.append(f'{ind}  <geom type="cylinder" size="0.008 0.005" pos="0 0 -0.005"/>')
            if f.get('spread_mimic'):
                eq.append(f'    <joint joint1="{n}_spread" joint2="{f["spread_mimic"]}" polycoef="0 1 0 0 0"/>')
            ind += '  '; close.append(ind[:-2] + '</body>')
            pos = f'{f["knuckle"]} 0 0'; q = qstr(qmul((1, 0, 0, 0), qy(f.get('pitch', 0.0))))
        else:
            pos = f'{base[0] + f["knuckle"] * math.cos(yaw):.6f} {base[1] + f["knuckle"] * math.sin(yaw):.6f} {base[2]}'; q = qstr(qmul(qz(yaw), qy(f.get('pitch', 0.0))))
        s.append(f'{ind}<body name="{n}_link_1" pos="{pos}" quat="{q}">')
        s.append(f'{ind}  <joint name="{n}_joint_1" axis="0 -1 0" range="{lo1:.6f} {hi1:.6f}"/>')
        s.append(f'{ind}  <geom type="box" size="{l1/2} {w/2} {t/2}" pos="{l1/2} 0 0"/>')
        s.append(f'{ind}  <body name="{n}_link_2" pos="{l1} 0 0">')
        s.append(f'{ind}    <joint name="{n}_joint_2" axis="0 -1 0" range="{lo2:.6f} {hi2:.6f}"/>')
        cx, cz = l2 / 2 * math.cos(b), l2 / 2 * math.sin(b)
        s.append(f'{ind}    <geom type="box" size="{l2/2} {w/2} {t/2}" pos="{cx:.6f} 0 {cz:.6f}" quat="{quat_y(-b)}"/>')
        s.append(f'{ind}  </body>')
        s.append(f'{ind}</body>')
        s.extend(reversed(close))
        if f.get('mimic'):
            eq.append(f'    <joint joint1="{n}_joint_2" joint2="{n}_joint_1" polycoef="0 {f["mimic"]} 0 0 0"/>')
    s += ['    </body>', '  </worldbody>']
    if eq:
        s += ['  <equality>'] + eq + ['  </equality>']
    s.append('</mujoco>')
    return '\n'.join(s) + '\n'

d = math.radians
# BarrettHand BH8: the wrist frame at the palm centre, 84 mm (Dw) behind the palm surface along z.
bh8_f = dict(knuckle=0.05, l1=0.07, l2=0.05, bend=42.0, r1=(0.0, d(140)), r2=(0.0, d(48)), box=(0.020, 0.018), mimic=0.3333)
bh8 = [dict(bh8_f, name='f1', base=(0.0, 0.025, 0.084), yaw=0.0, spread=True, spread_axis=-1),
       dict(bh8_f, name='f2', base=(0.0, -0.025, 0.084), yaw=0.0, spread=True, spread_axis=1, spread_mimic='f1_spread'),
       dict(bh8_f, name='f3', base=(0.0, 0.0, 0.084), yaw=math.pi)]
bh8_palm_u = '<collision><origin xyz="0 0 0.079"/><geometry><box size="0.1 0.08 0.01"/></geometry></collision>'
bh8_palm_m = '<geom type="box" size="0.05 0.04 0.005" pos="0 0 0.079"/>'
hdr_bh8 = '''<!-- BarrettHand BH8-series (BH8-262/280/282) for grasp-sim, written from the BH8-Series User's
     Manual (Barrett Technology, document D3000, section 9.5 "Kinematics"): Aw = 25 mm, A1 = 50 mm,
     A2 = 70 mm, A3 = 50 mm, Dw = 84 mm, the outer link's fixed bend Phi3 = 42 deg; inner link
     0-140 deg, outer 0-48 deg (zero: the finger straight out along the palm); the outer link
     coupled to the inner at 1/3 (Barrett's BH8-280 drive ratios, 125:1 and 93.75:1:
     assets/hands/README.md). Link cross-sections (20 x 18 mm) and the palm plate
     (100 x 80 x 10 mm) are PROVISIONAL. Generated by assets/hands/gen_hand_files.py. -->'''
# Schunk SDH-2, as its published robot description and library give it (README.md: sources).
# Metres. The palm link's frame: z out of the palm towards the fingers, the thumb on -x.
SDH_PALM = ((-0.0100, 0.0, 0.0357), (0.1138, 0.1234, 0.0772))  # box centre, size (palm mesh extents)
SDH_BASE_Z = 0.0745      # knuckle base above the palm link's origin
SDH_KNUCKLE = (0.0224, 0.0305)  # knuckle housing: radius, height above its base
SDH_FLEX_Z = 0.0165      # proximal flexion axis above the knuckle base
SDH_L1, SDH_L2 = 0.0865, 0.0685  # proximal joint to distal joint, distal joint to fingertip
# Link sections across the flexion plane (x: back, front towards the palm centre), width.
SDH_P1 = (-0.01465, 0.01465, 0.0278)  # 29.3 mm thick (mesh: -14.0 to +15.3), centred on the axis
SDH_P2 = SDH_P1  # the distal mesh's front is 14.85 mm: the same section, so both links are straight at 0
SDH_FINGERS = [  # name, knuckle joint (None: fixed to the palm), base xy, yaw, knuckle axis z sign, mimic
    ('finger_1', 'knuckle_joint', (0.01905, 0.033), math.pi, 1, None),
    ('finger_2', 'finger_21_joint', (0.01905, -0.033), math.pi, -1, 'knuckle_joint'),
    ('thumb', None, (-0.03811, 0.0), 0.0, 0, None),
]
SDH_JOINT_NAMES = {'finger_1': ('finger_12_joint', 'finger_13_joint'),
                   'finger_2': ('finger_22_joint', 'finger_23_joint'),
                   'thumb': ('thumb_2_joint', 'thumb_3_joint')}

def sdh_box(sec, length):
    lo, hi, w = sec
    return ((lo + hi) / 2, 0.0, length / 2), (hi - lo, w, length)

def sdh2_urdf(header):
    s = ['<?xml version="1.0"?>', header, '<robot name="sdh2">']
    (c, z) = SDH_PALM
    s.append(f'  <link name="palm"><collision><origin xyz="{c[0]} {c[1]} {c[2]}"/><geometry><box size="{z[0]} {z[1]} {z[2]}"/></geometry></collision></link>')
    r, h = SDH_KNUCKLE
    knuckle = f'<collision><origin xyz="0 0 {h/2}"/><geometry><cylinder radius="{r}" length="{h}"/></geometry></collision>'
    lim = f'lower="{-math.pi/2:.9f}" upper="{math.pi/2:.9f}" effort="1" velocity="1"'
    for name, kj, (x, y), yaw, zs, mimic in SDH_FINGERS:
        s.append(f'  <link name="{name}_knuckle">{knuckle}</link>')
        origin = f'<origin xyz="{x} {y} {SDH_BASE_Z}" rpy="0 0 {yaw:.9f}"/>'
        if kj:
            m = f'<mimic joint="{mimic}" multiplier="1" offset="0"/>' if mimic else ''
            s.append(f'  <joint name="{kj}" type="revolute"><parent link="palm"/><child link="{name}_knuckle"/>{origin}'
                     f'<axis xyz="0 0 {zs}"/><limit lower="0" upper="{math.pi/2:.9f}" effort="1" velocity="1"/>{m}</joint>')
        else:
            s.append(f'  <joint name="{name}_knuckle_joint" type="fixed"><parent link="palm"/><child link="{name}_knuckle"/>{origin}</joint>')
        j2, j3 = SDH_JOINT_NAMES[name]
        for link, sec, length in ((f'{name}_proximal', SDH_P1, SDH_L1), (f'{name}_distal', SDH_P2, SDH_L2)):
            (bc, bs) = sdh_box(sec, length)
            s.append(f'  <link name="{link}"><collision><origin xyz="{bc[0]:.6f} {bc[1]} {bc[2]:.6f}"/><geometry><box size="{bs[0]:.6f} {bs[1]} {bs[2]}"/></geometry></collision></link>')
        s.append(f'  <joint name="{j2}" type="revolute"><parent link="{name}_knuckle"/><child link="{name}_proximal"/>'
                 f'<origin xyz="0 0 {SDH_FLEX_Z}"/><axis xyz="0 1 0"/><limit {lim}/></joint>')
        s.append(f'  <joint name="{j3}" type="revolute"><parent link="{name}_proximal"/><child link="{name}_distal"/>'
                 f'<origin xyz="0 0 {SDH_L1}"/><axis xyz="0 1 0"/><limit {lim}/></joint>')
    s.append('</robot>')
    return '\n'.join(s) + '\n'

def sdh2_mjcf(header):
    s = [header, '<mujoco model="sdh2">', '  <compiler angle="radian"/>', '  <worldbody>', '    <body name="palm">']
    (c, z) = SDH_PALM
    s.append(f'      <geom type="box" size="{z[0]/2} {z[1]/2} {z[2]/2}" pos="{c[0]} {c[1]} {c[2]}"/>')
    r, h = SDH_KNUCKLE
    eq = []
    rng = f'range="{-math.pi/2:.9f} {math.pi/2:.9f}"'
    for name, kj, (x, y), yaw, zs, mimic in SDH_FINGERS:
        s.append(f'      <body name="{name}_knuckle" pos="{x} {y} {SDH_BASE_Z}" quat="{quat_z(yaw)}">')
        if kj:
            s.append(f'        <joint name="{kj}" axis="0 0 {zs}" range="0 {math.pi/2:.9f}"/>')
            if mimic:
                eq.append(f'    <joint joint1="{kj}" joint2="{mimic}" polycoef="0 1 0 0 0"/>')
        s.append(f'        <geom type="cylinder" size="{r} {h/2}" pos="0 0 {h/2}"/>')
        j2, j3 = SDH_JOINT_NAMES[name]
        (bc1, bs1), (bc2, bs2) = sdh_box(SDH_P1, SDH_L1), sdh_box(SDH_P2, SDH_L2)
        s.append(f'        <body name="{name}_proximal" pos="0 0 {SDH_FLEX_Z}">')
        s.append(f'          <joint name="{j2}" axis="0 1 0" {rng}/>')
        s.append(f'          <geom type="box" size="{bs1[0]/2:.6f} {bs1[1]/2} {bs1[2]/2}" pos="{bc1[0]:.6f} 0 {bc1[2]:.6f}"/>')
        s.append(f'          <body name="{name}_distal" pos="0 0 {SDH_L1}">')
        s.append(f'            <joint name="{j3}" axis="0 1 0" {rng}/>')
        s.append(f'            <geom type="box" size="{bs2[0]/2:.6f} {bs2[1]/2} {bs2[2]/2}" pos="{bc2[0]:.6f} 0 {bc2[2]:.6f}"/>')
        s.append('          </body>')
        s.append('        </body>')
        s.append('      </body>')
    s += ['    </body>', '  </worldbody>', '  <equality>'] + eq + ['  </equality>', '</mujoco>']
    return '\n'.join(s) + '\n'

hdr_sdh = '''<!-- Schunk SDH-2 (servo-electric 3-finger hand) for grasp-sim, written from its published
     numbers (assets/hands/README.md cites them): proximal link 86.5 mm and distal link 68.5 mm
     (joint to fingertip), finger bases on an equilateral triangle of 66 mm side (thumb 38.11 mm
     from the centre, fingers 1 and 2 at 19.05 mm, 33 mm either side), knuckle bases 74.5 mm above
     the palm link's origin, the proximal axes 16.5 mm above them; both flexion joints -90..+90 deg
     (zero: the finger standing straight up from the palm, positive closing), the knuckle joint
     0..90 deg turning fingers 1 and 2 about their base axes in opposite senses (0: both
     parallel, opposing the thumb). Boxes and cylinders span the published meshes' extents (palm
     113.8 x 123.4 x 77.2 mm, knuckle housings 44.8 mm across and 30.5 mm tall, link sections
     29.3 x 27.8 mm). Generated by assets/hands/gen_hand_files.py. -->'''
open('bh8.urdf', 'w').write(urdf('bh8', hdr_bh8, bh8_palm_u, bh8, []))
open('bh8.xml', 'w').write(mjcf('bh8', hdr_bh8, bh8_palm_m, bh8))
open('sdh2.urdf', 'w').write(sdh2_urdf(hdr_sdh))
open('sdh2.xml', 'w').write(sdh2_mjcf(hdr_sdh))
