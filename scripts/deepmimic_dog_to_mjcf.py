#!/usr/bin/python3
"""Converts DeepMimic's dog3d character into mimic2d's dog (docs/quadruped.md).

Reads DeepMimic's character file (skeleton, collision bodies, masses, torque
limits) and writes
  assets/skeletons/dog.yaml   the kinematic tree in mimic2d's convention
  assets/skeletons/dog.ap10k.yaml  its AP-10K keypoints
  assets/characters/dog.xml   the MuJoCo model: bodies, hinges, PD servos,
                              keypoint sites
Usage (from the repository's root; the character file is MIT, DeepMimic):
  scripts/deepmimic_dog_to_mjcf.py ../shared/data/deepmimic/characters/dog3d.txt

Conventions. DeepMimic is Y up, the dog faces +x and its left is -z;
mimic2d is Z up, facing +x, left +y: a point (x, y, z) maps to (x, -z, y),
the rotation motion/deepmimic_reader.cc applies to motions. Spherical joints
become three hinges about x, y, z (R = Rx Ry Rz, as the humanoid's);
DeepMimic's revolute joints turn about their z, which maps to -y.

PD gains (kp, kd) are DeepMimic's dog3d controller settings
(data/controllers/dog3d_ctrl.txt there), which its character file does not
hold; they are written out below. Only the standard library is used.
"""
import json
import math
import sys

# DeepMimic's dog3d controller: joint -> (kp N m/rad, kd N m s/rad).
PD_GAINS = {
    "spine0": (500, 50), "spine1": (500, 50), "neck": (100, 10),
    "head": (50, 5),
    "left_shoulder": (200, 20), "left_forearm": (200, 20),
    "left_hand": (100, 10), "left_finger": (50, 5),
    "right_shoulder": (200, 20), "right_forearm": (200, 20),
    "right_hand": (100, 10), "right_finger": (50, 5),
    "left_upper_leg": (300, 30), "left_leg": (200, 20),
    "left_foot": (150, 15), "left_toe": (80, 8),
    "right_upper_leg": (300, 30), "right_leg": (200, 20),
    "right_foot": (150, 15), "right_toe": (80, 8),
    "tail0": (20, 2), "tail1": (10, 1),
}

# Hinge ranges (deg) per spherical joint, x / y / z in mimic2d's axes (x:
# roll about the body's length, y: pitch, z: yaw). DeepMimic leaves its
# spherical joints unlimited; these bound the PD targets (the action maps
# [-1, 1] onto a range) and cover the dog3d clips' poses (each frame's Euler
# angles as PoseToQpos picks them) with a margin of 15 deg or more
# (docs/quadruped.md, "Joint ranges").
SPHERICAL_RANGES_DEG = {
    "spine0": ((-45, 45), (-60, 60), (-60, 60)),
    "spine1": ((-45, 45), (-60, 60), (-90, 90)),
    "neck": ((-60, 60), (-90, 90), (-90, 90)),
    "head": ((-90, 90), (-120, 120), (-110, 110)),
    "shoulder": ((-60, 60), (-120, 120), (-90, 90)),
    "hand": ((-120, 120), (-150, 150), (-110, 110)),
    "finger": ((-60, 60), (-120, 120), (-45, 45)),
    "upper_leg": ((-75, 75), (-120, 120), (-75, 75)),
    "foot": ((-75, 75), (-120, 120), (-90, 90)),
    "toe": ((-45, 45), (-90, 90), (-45, 45)),
    # The clips twist the tail about its length (x) all the way round.
    "tail0": ((-180, 180), (-90, 90), (-90, 90)),
    "tail1": ((-180, 180), (-90, 90), (-90, 90)),
}

# Bodies that may touch the ground in normal motion: DeepMimic's
# EnableFallContact 0 (the paws), listed in the character config.

# AP-10K keypoints (MMPose's animal layout): the joint each rides on and its
# offset in DeepMimic's axes in that joint's frame (the rest pose has the
# head's snout pointing down, -y; the clips turn it forward).
KEYPOINTS = [
    ("left_eye", "head", (0.125, -0.03, -0.03)),
    ("right_eye", "head", (0.125, -0.03, 0.03)),
    ("nose", "head", (0.09, -0.135, 0.0)),
    ("neck", "neck", (0.0, 0.0, 0.0)),
    ("root_of_tail", "tail0", (0.0, 0.0, 0.0)),
    ("left_shoulder", "left_shoulder", (0.0, 0.0, 0.0)),
    ("left_elbow", "left_forearm", (0.0, 0.0, 0.0)),
    ("left_front_paw", "left_finger", (0.012, -0.02, 0.0)),
    ("right_shoulder", "right_shoulder", (0.0, 0.0, 0.0)),
    ("right_elbow", "right_forearm", (0.0, 0.0, 0.0)),
    ("right_front_paw", "right_finger", (0.012, -0.02, 0.0)),
    ("left_hip", "left_upper_leg", (0.0, 0.0, 0.0)),
    ("left_knee", "left_leg", (0.0, 0.0, 0.0)),
    ("left_back_paw", "left_toe", (0.015, -0.02, 0.0)),
    ("right_hip", "right_upper_leg", (0.0, 0.0, 0.0)),
    ("right_knee", "right_leg", (0.0, 0.0, 0.0)),
    ("right_back_paw", "right_toe", (0.015, -0.02, 0.0)),
]

ARMATURE = 0.01  # kg m^2 per hinge: steadies the light paws at 120 Hz


def to_world(v):
    """DeepMimic's Y-up axes to mimic2d's Z-up axes."""
    x, y, z = v
    return (x, -z, y)


def fmt(values):
    return " ".join("%.6g" % (0.0 if abs(v) < 1e-6 else v) for v in values)


def rotate_z(v, angle):
    c, s = math.cos(angle), math.sin(angle)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1], v[2])


def write_lines(path, lines):
    with open(path, "w") as out:
        out.write("\n".join(lines) + "\n")


def range_class(name):
    """The SPHERICAL_RANGES_DEG key of a joint."""
    for side in ("left_", "right_"):
        if name.startswith(side):
            return name[len(side):]
    return name


def geom_xml(body, indent):
    """The collision geom of a DeepMimic body, in the joint's frame."""
    name, shape, mass = body["Name"], body["Shape"], body["Mass"]
    if body["AttachThetaX"] != 0 or body["AttachThetaY"] != 0:
        sys.exit("%s: only rotations about z are converted" % name)
    centre = (body["AttachX"], body["AttachY"], body["AttachZ"])
    p = (body["Param0"], body["Param1"], body["Param2"])
    common = 'name="%s" mass="%g"' % (name, mass)
    if shape == "sphere":
        return '%s<geom %s type="sphere" pos="%s" size="%g"/>' % (
            indent, common, fmt(to_world(centre)), p[0] / 2)
    if shape == "box":
        if body["AttachThetaZ"] != 0:
            sys.exit("%s: rotated boxes are not converted" % name)
        half = to_world((p[0] / 2, p[1] / 2, p[2] / 2))
        return '%s<geom %s type="box" pos="%s" size="%s"/>' % (
            indent, common, fmt(to_world(centre)), fmt(abs(h) for h in half))
    if shape == "capsule":
        # DeepMimic's capsule: diameter Param0, cylinder length Param1 along
        # the body's y axis turned by AttachThetaZ.
        axis = rotate_z((0.0, 1.0, 0.0), body["AttachThetaZ"])
        half = p[1] / 2
        a = [c - half * d for c, d in zip(centre, axis)]
        b = [c + half * d for c, d in zip(centre, axis)]
        return '%s<geom %s type="capsule" fromto="%s %s" size="%g"/>' % (
            indent, common, fmt(to_world(a)), fmt(to_world(b)), p[0] / 2)
    sys.exit("%s: unknown shape %s" % (name, shape))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    character = json.load(open(sys.argv[1]))
    joints = character["Skeleton"]["Joints"]
    bodies = {b["ID"]: b for b in character["BodyDefs"]}
    children = {}
    for j in joints:
        children.setdefault(j["Parent"], []).append(j)
        if any(j["AttachTheta" + a] != 0 for a in "XYZ"):
            sys.exit("%s: rotated joint frames are not converted" % j["Name"])
    keypoints_of = {}
    for name, joint, offset in KEYPOINTS:
        keypoints_of.setdefault(joint, []).append((name, offset))

    # Standing height: the lowest point of the rest pose (legs straight down)
    # on the floor.
    def lowest(joint, origin):
        body = bodies[joint["ID"]]
        low = origin[1] + body["AttachY"] - body["Param1"] / 2
        for child in children.get(joint["ID"], []):
            low = min(low, lowest(child, (origin[0] + child["AttachX"],
                                          origin[1] + child["AttachY"])))
        return low
    root = joints[0]
    standing_z = -lowest(root, (0.0, 0.0))

    # ---- skeleton YAML ----
    skeleton = [
        "# DeepMimic's dog3d kinematic tree (23 joints), world convention: Z up,",
        "# the dog faces +x, its left is +y. Offsets (m) are the parent-frame",
        "# positions of each joint. Joint order is DeepMimic's channel order.",
        "# Written by scripts/deepmimic_dog_to_mjcf.py (docs/quadruped.md).",
        "name: dog",
        "joints:",
        "  - {name: root, type: free, offset_m: [0, 0, 0]}",
    ]
    for j in joints[1:]:
        offset = fmt(to_world((j["AttachX"], j["AttachY"], j["AttachZ"])))
        parent = joints[j["Parent"]]["Name"]
        line = "  - {name: %s, parent: %s, type: %s, offset_m: [%s]" % (
            j["Name"], parent, j["Type"], offset.replace(" ", ", "))
        if j["Type"] == "revolute":
            line += ", axis: [0, -1, 0]"
        skeleton.append(line + "}")
    write_lines("assets/skeletons/dog.yaml", skeleton)

    # ---- keypoint map YAML ----
    keypoint_map = [
        "# AP-10K keypoints (MMPose's animal layout) on the dog skeleton",
        "# (dog.yaml): the joint each rides on and its offset in that joint's",
        "# frame (m, Z up, facing +x, left +y; the rest pose's snout points",
        "# down). The MJCF carries a site at each (assets/characters/dog.xml).",
        "# Written by scripts/deepmimic_dog_to_mjcf.py (docs/quadruped.md).",
        "layout: ap10k",
        "keypoints:",
    ]
    for name, joint, offset in KEYPOINTS:
        keypoint_map.append("  %s: {joint: %s, offset_m: [%s]}" % (
            name, joint, fmt(to_world(offset)).replace(" ", ", ")))
    write_lines("assets/skeletons/dog.ap10k.yaml", keypoint_map)

    # ---- MJCF ----
    lines = [
        "<!-- The DeepMimic dog3d quadruped for mimic2d (docs/quadruped.md).",
        "     Written by scripts/deepmimic_dog_to_mjcf.py from DeepMimic's",
        "     character file (MIT): 23 bodies, geometry, masses and torque",
        "     limits are DeepMimic's; PD gains its dog3d controller's; hinge",
        "     ranges and armature the script's. Spherical joints are three",
        "     hinges about x, y, z (R = Rx Ry Rz); elbows and knees one hinge",
        "     about -y. Z up, metres, faces +x, left is +y. Body offsets equal",
        "     assets/skeletons/dog.yaml. PD control: a `position` actuator per",
        "     hinge gives kp, joint `damping` gives kd (implicit in MuJoCo's",
        "     Euler integrator). Sites kp_<keypoint> are the AP-10K keypoints",
        "     of assets/skeletons/dog.ap10k.yaml. No floor: scenes add it. -->",
        '<mujoco model="dog">',
        '  <compiler angle="degree"/>',
        "  <default>",
        '    <default class="dog">',
        '      <geom condim="1" friction="1.0 0.05 0.05" solimp=".9 .99 .003"',
        '            solref=".015 1" rgba=".71 .55 .38 1"/>',
        '      <joint type="hinge" limited="true" solimplimit="0 .99 .01"',
        '             stiffness="0" armature="%g"/>' % ARMATURE,
        '      <site type="sphere" size=".02" rgba="1 .5 0 1" group="4"/>',
        '      <position ctrllimited="false" forcelimited="true"/>',
        "    </default>",
        "  </default>",
        "  <worldbody>",
    ]
    actuators = []

    def emit(joint, pos, depth):
        indent = "  " * depth
        name = joint["Name"]
        if joint["Parent"] < 0:
            lines.append('%s<!-- Standing height: the rest pose\'s lowest point'
                         ' on the floor. -->' % indent)
            lines.append('%s<body name="%s" pos="0 0 %.6g" childclass="dog">'
                         % (indent, name, standing_z))
            lines.append('%s  <freejoint name="root"/>' % indent)
        else:
            lines.append('%s<body name="%s" pos="%s">' % (indent, name,
                                                          fmt(pos)))
            kp, kd = PD_GAINS[name]
            torque = joint["TorqueLim"]
            if joint["Type"] == "spherical":
                ranges = SPHERICAL_RANGES_DEG[range_class(name)]
                hinges = [("%s_%s" % (name, a), ax, r) for a, ax, r in
                          zip("xyz", ("1 0 0", "0 1 0", "0 0 1"), ranges)]
            else:
                low, high = joint["LimLow0"], joint["LimHigh0"]
                hinges = [(name, "0 -1 0", (math.degrees(low),
                                            math.degrees(high)))]
            for hinge, axis, (low, high) in hinges:
                lines.append('%s  <joint name="%s" axis="%s" range="%g %g" '
                             'damping="%g"/>' % (indent, hinge, axis, low,
                                                 high, kd))
                actuators.append('    <position name="%s" joint="%s" kp="%g" '
                                 'forcerange="%g %g" class="dog"/>'
                                 % (hinge, hinge, kp, -torque, torque))
        lines.append(geom_xml(bodies[joint["ID"]], indent + "  "))
        for kp_name, offset in keypoints_of.get(name, []):
            lines.append('%s  <site name="kp_%s" pos="%s"/>' % (
                indent, kp_name, fmt(to_world(offset))))
        for child in children.get(joint["ID"], []):
            emit(child, to_world((child["AttachX"], child["AttachY"],
                                  child["AttachZ"])), depth + 1)
        lines.append("%s</body>" % indent)

    emit(root, None, 2)
    lines.append("  </worldbody>")
    lines.append("  <!-- One position servo per hinge, in the character "
                 "config's joint order")
    lines.append("       (assets/characters/dog.yaml): the action order. -->")
    lines.append("  <actuator>")
    lines.extend(actuators)
    lines.append("  </actuator>")
    lines.append("</mujoco>")
    write_lines("assets/characters/dog.xml", lines)


if __name__ == "__main__":
    main()
