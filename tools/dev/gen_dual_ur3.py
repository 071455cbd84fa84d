#!/usr/bin/env python3
"""Writes meshes/cell/dual_ur3.urdf: two UR3 arms on the dual-arm body, each with an FT300 and a
Robotiq 2F-85. Joint origins follow the UR3 DH table exactly (link frames = DH frames, so the
analytic IK needs no offsets); collision geometry is primitives sized from the UR3 and 2F-85
datasheets (within about 1 cm). Run from the repository root: tools/dev/gen_dual_ur3.py"""
import math

D1, A2, A3, D4, D5, D6 = 0.1519, -0.24365, -0.21325, 0.11235, 0.08535, 0.0819
ALPHA = [math.pi / 2, 0, 0, math.pi / 2, -math.pi / 2, 0]
D = [D1, 0, 0, D4, D5, D6]
A = [0, A2, A3, 0, 0, 0]
VEL = [math.radians(v) for v in (180, 180, 180, 360, 360, 360)]
EFFORT = [56, 56, 28, 12, 12, 12]
LINKS = ["shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
         "wrist_3_link"]
JOINTS = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
          "wrist_2_joint", "wrist_3_joint"]
# Lateral offsets of the real links along the joint axes (UR3 shoulder/elbow/wrist offsets).
SHOULDER_OFFSET, ELBOW_OFFSET = 0.1198, -0.0925
FOREARM_Z = SHOULDER_OFFSET + ELBOW_OFFSET


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def rx(t):
    c, s = math.cos(t), math.sin(t)
    return [[1, 0, 0], [0, c, -s], [0, s, c]]


def rz(t):
    c, s = math.cos(t), math.sin(t)
    return [[c, -s, 0], [s, c, 0], [0, 0, 1]]


def rpy(r):
    pitch = math.atan2(-r[2][0], math.hypot(r[0][0], r[1][0]))
    roll = math.atan2(r[2][1], r[2][2])
    yaw = math.atan2(r[1][0], r[0][0])
    return roll, pitch, yaw


def f(x):
    x = float(x)
    if x == 0:
        return "0"
    s = repr(x)  # shortest string that reads back to the same double
    return s[:-2] if s.endswith(".0") else s


def origin(xyz=(0, 0, 0), r=(0, 0, 0)):
    return '<origin xyz="%s %s %s" rpy="%s %s %s"/>' % tuple(f(v) for v in (*xyz, *r))


def cyl(radius, length, xyz=(0, 0, 0), r=(0, 0, 0)):
    return ('<collision>%s<geometry><cylinder radius="%s" length="%s"/></geometry></collision>'
            % (origin(xyz, r), f(radius), f(length)))


def box(size, xyz=(0, 0, 0), r=(0, 0, 0)):
    return ('<collision>%s<geometry><box size="%s %s %s"/></geometry></collision>'
            % (origin(xyz, r), *(f(v) for v in size)))


def cyl_z(radius, z0, z1, x=0.0, y=0.0):
    return cyl(radius, z1 - z0, (x, y, (z0 + z1) / 2))


def cyl_x(radius, x0, x1, z=0.0):
    return cyl(radius, abs(x1 - x0), ((x0 + x1) / 2, 0, z), (0, math.pi / 2, 0))


def link(name, *collisions):
    body = "".join(collisions)
    return '  <link name="%s">%s</link>\n' % (name, body)


def joint(name, kind, parent, child, xyz=(0, 0, 0), r=(0, 0, 0), axis=None, limit=None, mimic=None):
    s = '  <joint name="%s" type="%s"><parent link="%s"/><child link="%s"/>%s' % (
        name, kind, parent, child, origin(xyz, r))
    if axis:
        s += '<axis xyz="%s %s %s"/>' % tuple(f(v) for v in axis)
    if limit:
        s += '<limit lower="%s" upper="%s" velocity="%s" effort="%s"/>' % tuple(f(v) for v in limit)
    if mimic:
        s += '<mimic joint="%s" multiplier="1" offset="0"/>' % mimic
    return s + "</joint>\n"


def arm(side, mount_xyz, mount_r):
    p = side + "_"
    out = joint(p + "base_mount", "fixed", "torso", p + "base_link", mount_xyz, rpy(mount_r))
    # UR3 base: 128 mm diameter foot up to the shoulder housing.
    out += link(p + "base_link", cyl_z(0.064, 0.0, 0.075))
    geoms = [
        # shoulder: pan housing (90 mm) up to just above the lift axis
        [cyl_z(0.045, 0.075, D1 + 0.045)],
        # upper arm: lift housing along its axis, tube at the shoulder offset
        [cyl_z(0.045, 0.03, SHOULDER_OFFSET + 0.045), cyl_x(0.032, 0.0, A2, SHOULDER_OFFSET)],
        # forearm: elbow housing, tube at the forearm offset
        [cyl_z(0.040, FOREARM_Z - 0.035, SHOULDER_OFFSET + 0.040), cyl_x(0.028, 0.0, A3, FOREARM_Z)],
        # wrist 1 housing (63 mm) from the forearm tube to the wrist-2 axis
        [cyl_z(0.032, FOREARM_Z - 0.03, D4 + 0.0)],
        # wrist 2 housing along its axis up to the wrist-3 axis
        [cyl_z(0.032, -0.032, D5)],
        # wrist 3 housing up to the tool flange
        [cyl_z(0.032, -0.032, D6)],
    ]
    parent = p + "base_link"
    prev_xyz, prev_r = (0, 0, 0), (0, 0, 0)
    for i in range(6):
        # The elbow cannot pass +-pi (the forearm folds onto the upper arm), so, as in Universal
        # Robots' own ROS description, its limits are +-pi; the other joints turn twice.
        turn = math.pi if JOINTS[i] == "elbow_joint" else 2 * math.pi
        out += joint(p + JOINTS[i], "revolute", parent, p + LINKS[i], prev_xyz, prev_r, (0, 0, 1),
                     (-turn, turn, VEL[i], EFFORT[i]))
        out += link(p + LINKS[i], *geoms[i])
        parent = p + LINKS[i]
        prev_xyz, prev_r = (A[i], 0, D[i]), (ALPHA[i], 0, 0)
    out += joint(p + "flange_joint", "fixed", parent, p + "tool0", prev_xyz, prev_r)
    out += link(p + "tool0")
    # Robotiq FT300 (75 mm x 37.5 mm) and coupling.
    out += joint(p + "ft_joint", "fixed", p + "tool0", p + "ft_sensor")
    out += link(p + "ft_sensor", cyl_z(0.0375, 0.0, 0.05))
    # 2F-85 chassis; the palm frame sits on the coupling, z along the approach.
    out += joint(p + "palm_joint", "fixed", p + "ft_sensor", p + "gripper_palm", (0, 0, 0.05))
    out += link(p + "gripper_palm", box((0.06, 0.10, 0.085), (0, 0, 0.0425)))
    # Fingers slide along +-y (the opening axis); joint value = half the jaw opening.
    for finger, sign in (("finger_l", 1), ("finger_r", -1)):
        mimic = None if sign > 0 else p + "finger_joint"
        name = p + ("finger_joint" if sign > 0 else "finger_r_joint")
        out += joint(name, "prismatic", p + "gripper_palm", p + finger, (0, 0, 0), (0, 0, 0),
                     (0, sign, 0), (0, 0.0425, 0.15, 235), mimic)
        # Finger body outside its pad; pad inner face at y = +-opening/2.
        out += link(p + finger, box((0.022, 0.012, 0.09), (0, sign * 0.014, 0.13)))
        out += joint(p + "pad_" + finger[-1] + "_joint", "fixed", p + finger,
                     p + "pad_" + finger[-1])
        out += link(p + "pad_" + finger[-1], box((0.022, 0.008, 0.037), (0, sign * 0.004, 0.15)))
    # Tool centre point between the pads, 0.20 m from the flange; y = opening axis.
    out += joint(p + "tcp_joint", "fixed", p + "gripper_palm", p + "tcp", (0, 0, 0.15))
    out += link(p + "tcp")
    return out


def main():
    s = '<?xml version="1.0"?>\n'
    s += "<!-- Generated by tools/dev/gen_dual_ur3.py; edit the generator, not this file. -->\n"
    s += '<robot name="dual_ur3">\n'
    s += link("world")
    s += joint("torso_joint", "fixed", "world", "torso")
    # Column from the floor stand to the chest, and the chest plate the arms are mounted on.
    s += link("torso", box((0.16, 0.20, 1.30), (-0.08, 0, 0.65)),
              box((0.20, 0.36, 0.42), (-0.10, 0, 1.52)))
    s += arm("left", (0, 0.2585, 1.6105), rx(math.radians(-135)))
    s += arm("right", (0, -0.2585, 1.6105), matmul(rx(math.radians(135)), rz(math.pi)))
    s += "</robot>\n"
    with open("meshes/cell/dual_ur3.urdf", "w") as fh:
        fh.write(s)


if __name__ == "__main__":
    main()
