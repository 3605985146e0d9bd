"""tools/scripts/blender_check.py — imports a magsim-scene --gltf file into a real Blender, headless,
and checks it against the run's states.csv.

  blender -b --factory-startup --python-exit-code 2 --python tools/scripts/blender_check.py -- \\
      FILE.glb states.csv FPS [--channels m_norm,speed]

It empties the scene, sets its fps (Blender keys a glTF time t at frame t × fps), imports the
file with import_shading='SMOOTH' (the default 'NORMALS' fails on numpy 1.24's np.bool), and
checks:
- at the first, second, middle and last recorded frame (key times only: Blender interpolates
  LINEAR rotations by nlerp), every body's world position within 1e-5 m of states.csv and its
  rotation within 1e-5 rad;
- one mesh datablock per distinct shape (kind, size, material), shared by all its objects;
- one object per glTF node: bodies (as many as states.csv has), shapes, channel nodes, the
  ground and the camera;
- every animated body keyed at exactly the frames of states.csv (frame t × fps);
- the camera at the scene's eye, looking at its target (the camera node's extras);
- with --channels: each body's "<body>.channels" object has Blender scale axis k = channel k,
  equal to the file's values at the checked frames, and, as a check independent of the file,
  m_norm of a body with only permanent moments equals |extras.moment| and speed and spin of a
  static body are 0.
Prints one line per check and the import time; exit 0 when all pass, 1 when one fails, 2 on
a Python error (--python-exit-code 2).
"""
import csv
import json
import math
import struct
import sys
import time

import bpy
from mathutils import Vector

POS_TOL = 1e-5  # m
ROT_TOL = 1e-5  # rad


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    channels = []
    if "--channels" in argv:
        i = argv.index("--channels")
        channels = [c for c in argv[i + 1].split(",") if c]
        del argv[i:i + 2]
    if len(argv) != 3:
        print("usage: blender -b --factory-startup --python-exit-code 2 --python blender_check.py -- "
              "FILE.glb states.csv FPS [--channels NAMES]", file=sys.stderr)
        sys.exit(1)
    return argv[0], argv[1], float(argv[2]), channels


def read_states(path):
    """frames: list of (time, {body: ((x, y, z), (w, x, y, z))}) in file order."""
    frames = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            k = int(row["frame"])
            t, poses = frames.setdefault(k, (float(row["time"]), {}))
            poses[int(row["body"])] = ((float(row["x"]), float(row["y"]), float(row["z"])),
                                       (float(row["qw"]), float(row["qx"]), float(row["qy"]), float(row["qz"])))
    return [frames[k] for k in sorted(frames)]


def read_glb(path):
    """The JSON chunk and the binary chunk of a .glb, read without Blender."""
    with open(path, "rb") as f:
        data = f.read()
    magic, version, length = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2 and length == len(data), "not a glTF 2.0 binary file"
    n, kind = struct.unpack_from("<II", data, 12)
    doc = json.loads(data[20:20 + n])
    bin_len, _ = struct.unpack_from("<II", data, 20 + n)
    return doc, data[28 + n:28 + n + bin_len]


def accessor_floats(doc, binary, index):
    a = doc["accessors"][index]
    v = doc["bufferViews"][a["bufferView"]]
    width = {"SCALAR": 1, "VEC3": 3, "VEC4": 4}[a["type"]]
    start = v.get("byteOffset", 0) + a.get("byteOffset", 0)
    flat = struct.unpack_from("<%df" % (a["count"] * width), binary, start)
    return [flat[i * width:(i + 1) * width] for i in range(a["count"])]


def rotation_angle(q1, q2):
    """The angle (rad) of the rotation between two unit quaternions (w, x, y, z), in doubles."""
    w1, x1, y1, z1 = q1
    w2, x2, y2, z2 = q2
    # conj(q1) * q2
    w = w1 * w2 + x1 * x2 + y1 * y2 + z1 * z2
    x = w1 * x2 - x1 * w2 - y1 * z2 + z1 * y2
    y = w1 * y2 + x1 * z2 - y1 * w2 - z1 * x2
    z = w1 * z2 - x1 * y2 + y1 * x2 - z1 * w2
    return 2 * math.atan2(math.sqrt(x * x + y * y + z * z), abs(w))


def angle_between(a, b):
    """The angle (rad) between two vectors, in doubles: atan2 keeps small angles exact."""
    cross = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    return math.atan2(math.sqrt(sum(x * x for x in cross)), sum(x * y for x, y in zip(a, b)))


class Checks:
    def __init__(self):
        self.failed = 0

    def check(self, ok, what):
        print(("ok    " if ok else "FAIL  ") + what, flush=True)
        if not ok:
            self.failed += 1


def main():
    glb, states_path, fps, channels = parse_args()
    c = Checks()
    frames = read_states(states_path)
    doc, binary = read_glb(glb)
    nbody = len(frames[0][1])

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = max(1, round(fps))
    scene.render.fps_base = scene.render.fps / fps
    key_fps = scene.render.fps  # the importer keys t at t × render.fps
    t0 = time.time()
    bpy.ops.import_scene.gltf(filepath=glb, import_shading="SMOOTH")
    print("import: %.2f s, %d objects, %d meshes, %d actions" % (time.time() - t0, len(bpy.data.objects),
                                                                len(bpy.data.meshes), len(bpy.data.actions)), flush=True)

    # objects
    nodes = doc["nodes"]
    c.check(len(bpy.data.objects) == len(nodes), "objects: %d, one per glTF node (%d)" % (len(bpy.data.objects), len(nodes)))
    bodies = {o["magsim_body"]: o for o in bpy.data.objects if "magsim_body" in o.keys()}
    c.check(sorted(bodies) == list(range(nbody)), "bodies: %d objects for the %d bodies of states.csv" % (len(bodies), nbody))

    # meshes: one datablock per distinct shape, every object of a shape on it
    shape_key = {}
    for i, n in enumerate(nodes):
        e = n.get("extras", {})
        if "shape" in e:
            mat = doc["meshes"][n["mesh"]]["primitives"][0].get("material")
            shape_key[n["name"]] = (e["shape"], tuple(e["size"]), mat)
    blocks = {}
    for o in bpy.data.objects:
        if o.type == "MESH" and o.name in shape_key:
            blocks.setdefault(shape_key[o.name], set()).add(o.data.name)
    shared = all(len(v) == 1 for v in blocks.values())
    distinct = len(set(shape_key.values()))
    ground = 1 if any(n.get("extras", {}).get("magsim_ground") for n in nodes) else 0
    c.check(shared and len(blocks) == distinct and len(bpy.data.meshes) == distinct + ground,
            "meshes: %d datablocks for %d distinct shapes (+%d ground) of %d shape objects" %
            (len(bpy.data.meshes), distinct, ground, len(shape_key)))

    # the camera: at the scene's eye, looking at its target, its up on the scene's up side
    cams = [o for o in bpy.data.objects if o.type == "CAMERA" and "magsim_camera" in o.keys()]
    if cams:
        want = cams[0]["magsim_camera"]
        m = cams[0].matrix_world
        eye, target, up = (Vector(want[k]) for k in ("eye", "target", "up"))
        fwd = m.to_3x3() @ Vector((0, 0, -1))
        cam_up = m.to_3x3() @ Vector((0, 1, 0))
        aim = angle_between(tuple(fwd), tuple(target - eye))
        c.check((m.to_translation() - eye).length <= POS_TOL and aim <= 1e-5 and cam_up.dot(up) > 0,
                "camera: at the scene's eye, %.1e rad off the line to its target" % aim)
    else:
        c.check(False, "camera: none in the file")

    # the keys: every animated body keyed at exactly the frames of states.csv, t × fps
    want_keys = [t * key_fps for t, _ in frames]
    keyed = off = 0
    worst_key = 0.0
    for o in bodies.values():
        action = o.animation_data.action if o.animation_data else None
        if action is None:
            continue
        keyed += 1
        curve = action.fcurves.find("location", index=0)
        keys = [k.co.x for k in curve.keyframe_points] if curve else []
        if len(keys) != len(want_keys):
            off += 1
            continue
        worst_key = max([worst_key] + [abs(a - b) for a, b in zip(keys, want_keys)])
    c.check(off == 0 and worst_key <= 1e-4 * max(1.0, want_keys[-1]),
            "keys: %d animated bodies keyed at the %d frames of states.csv (%d not; worst key %.1e frames off)" %
            (keyed, len(want_keys), off, worst_key))

    # poses at the first, second, middle and last frame
    picks = sorted({0, min(1, len(frames) - 1), len(frames) // 2, len(frames) - 1})
    for k in picks:
        t, poses = frames[k]
        f = t * key_fps
        scene.frame_set(int(math.floor(f)), subframe=f - math.floor(f))
        worst_p = worst_r = 0.0
        worst_body = None
        for b, (p, q) in poses.items():
            m = bodies[b].matrix_world
            loc = m.to_translation()
            dp = math.sqrt(sum((loc[i] - p[i]) ** 2 for i in range(3)))
            qb = m.to_3x3().normalized().to_quaternion()
            dr = rotation_angle(q, (qb.w, qb.x, qb.y, qb.z))
            if dp > worst_p or dr > worst_r:
                worst_body = b
            worst_p, worst_r = max(worst_p, dp), max(worst_r, dr)
        c.check(worst_p <= POS_TOL and worst_r <= ROT_TOL,
                "frame %d (t = %.6g s, Blender frame %.4f): %d bodies, position off by at most %.2e m, rotation "
                "by %.2e rad (body %s)" % (k, t, f, len(poses), worst_p, worst_r, worst_body))

    if channels:
        check_channels(c, doc, binary, bodies, channels, frames, picks, key_fps, scene)
    print("blender_check: %s (%s)" % ("all passed" if c.failed == 0 else "%d FAILED" % c.failed, glb), flush=True)
    sys.exit(0 if c.failed == 0 else 1)


def check_channels(c, doc, binary, bodies, channels, frames, picks, key_fps, scene):
    names = doc["scenes"][0].get("extras", {}).get("magsim_channels", [])
    c.check(names == channels, "channels in the file: %s (asked: %s)" % (names, channels))
    helpers = {}
    for o in bpy.data.objects:
        if "magsim_channels" in o.keys() and o.parent is not None and "magsim_body" in o.parent.keys():
            helpers[o.parent["magsim_body"]] = o
    c.check(len(helpers) == len(bodies), "channel objects: %d for %d bodies" % (len(helpers), len(bodies)))
    # the file's values: the scale channel of each helper node, glTF (x, y, z) = channels (0, 2, 1)
    anim = doc["animations"][0]
    scale_of = {}
    for ch in anim["channels"]:
        if ch["target"]["path"] == "scale":
            scale_of[ch["target"]["node"]] = accessor_floats(doc, binary, anim["samplers"][ch["sampler"]]["output"])
    worst = 0.0
    independent = []
    for k in picks:
        t = frames[k][0]
        f = t * key_fps
        scene.frame_set(int(math.floor(f)), subframe=f - math.floor(f))
        for b, o in helpers.items():
            n = next(i for i in doc["nodes"][b]["children"] if "magsim_channels" in doc["nodes"][i].get("extras", {}))
            s = scale_of[n][k]
            want = [s[0], s[2], s[1]]
            for i in range(len(channels)):
                got = o.scale[i]
                worst = max(worst, abs(got - want[i]) / max(1.0, abs(want[i])))
            extras = doc["nodes"][b].get("extras", {})
            for i, name in enumerate(channels):
                if name == "m_norm" and "moment" in extras and extras.get("induced_moments", 0) == 0:
                    m = math.sqrt(sum(x * x for x in extras["moment"]))
                    independent.append(abs(o.scale[i] - m) / max(m, 1e-30))
                if name in ("speed", "spin") and extras.get("type") == "static":
                    independent.append(abs(o.scale[i]))
    c.check(worst <= 1e-6, "channels: Blender's scale axes equal the file's values at the checked frames (worst "
            "relative difference %.1e)" % worst)
    if independent:
        c.check(max(independent) <= 1e-6, "channels: m_norm of the magnets = |moment|, speed and spin of static "
                "bodies = 0 (%d values, worst %.1e)" % (len(independent), max(independent)))


if __name__ == "__main__":
    main()
