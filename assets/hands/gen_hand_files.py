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
     A2 = 70 mm, A3 = 50 mm, Dw = 84 mm, the outer link's fixed bend (42 deg, as assets/hands/bh8.toml
     reads it); inner link 0-140 deg, outer 0-48 deg (zero: the finger straight out along the palm).
     Link cross-sections (20 x 18 mm), the palm plate (100 x 80 x 10 mm) and the coupling's ratio
     (the TorqueSwitch drives the outer link with the inner, about a third as far, until the inner
     stalls) are PROVISIONAL. Generated by assets/hands/gen_hand_files.py. -->'''
sdh_f = dict(knuckle=0.0, l1=0.0865, l2=0.0685, bend=0.0, r1=(d(-90), d(90)), r2=(d(-90), d(90)), box=(0.016, 0.016))
# Schunk SDH-2: finger bases on an equilateral triangle of 66 mm side; the two fingers turn about
# their base axes (coupled, the knuckle joint); at 0 they stand parallel, opposing the thumb.
r = 0.066 / math.sqrt(3)
sdh = [dict(sdh_f, name='finger_1', base=(r / 2, 0.033, 0.0), yaw=0.0, spread=True, spread_axis=1),
       dict(sdh_f, name='finger_3', base=(r / 2, -0.033, 0.0), yaw=0.0, spread=True, spread_axis=-1, spread_mimic='finger_1_spread'),
       dict(sdh_f, name='thumb', base=(-r, 0.0, 0.0), yaw=math.pi)]
for f in sdh:
    f['pitch'] = -math.pi / 2
sdh_palm_u = '<collision><origin xyz="0 0 -0.01"/><geometry><cylinder radius="0.05" length="0.02"/></geometry></collision>'
sdh_palm_m = '<geom type="cylinder" size="0.05 0.01" pos="0 0 -0.01"/>'
hdr_sdh = '''<!-- Schunk SDH-2 (servo-electric 3-finger hand) for grasp-sim, written from SCHUNK's SDH-2
     datasheet and operating manual: finger bases on an equilateral triangle of 66 mm side, proximal
     link 86.5 mm and distal link 68.5 mm (joint to fingertip), both joints -90..+90 deg (zero: the
     finger standing straight up from the palm), the knuckle joint turning fingers 1 and 3 about
     their base axes in opposite senses (0 deg: both parallel, opposing the thumb). The palm disc
     (100 mm across, 20 mm deep), the 26 x 26 mm link sections and the flexion axes level with the
     palm face are PROVISIONAL. Generated by assets/hands/gen_hand_files.py. -->'''
def zero_up(fs):
    # SDH-2: zero is the finger standing up: turn phalanx 1 up from the palm with the base frame.
    return fs
open('bh8.urdf', 'w').write(urdf('bh8', hdr_bh8, bh8_palm_u, bh8, []))
open('bh8.xml', 'w').write(mjcf('bh8', hdr_bh8, bh8_palm_m, bh8))
open('sdh2.urdf', 'w').write(urdf('sdh2', hdr_sdh, sdh_palm_u, sdh, []))
open('sdh2.xml', 'w').write(mjcf('sdh2', hdr_sdh, sdh_palm_m, sdh))
