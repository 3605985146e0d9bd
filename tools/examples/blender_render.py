"""tools/examples/blender_render.py — imports a magsim-scene --gltf file into headless Blender and
renders one still with Cycles on the CPU (no GPU needed).

  blender -b --factory-startup --python-exit-code 2 --python tools/examples/blender_render.py -- \\
      FILE.glb OUT.png [--time T] [--fps 60] [--samples 16] [--size 960x540] [--color-by CHANNEL]

--time picks the moment (s; default: the last key), --color-by colours each body by one of the
file's channels (--gltf-channels; the value is the scale of the body's "<body>.channels" object,
Blender axis k = channel k), from blue (0) to orange (the largest value in the still). The file
brings the bodies, their materials, the ground and the camera; this script adds a sun along the
preview renderer's light and its background colour.
"""
import math
import sys

import bpy
from mathutils import Vector


def parse_args():
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    opts = {"--time": None, "--fps": "60", "--samples": "16", "--size": "960x540", "--color-by": None}
    pos = []
    i = 0
    while i < len(argv):
        if argv[i] in opts:
            opts[argv[i]] = argv[i + 1]
            i += 2
        else:
            pos.append(argv[i])
            i += 1
    if len(pos) != 2:
        print(__doc__, file=sys.stderr)
        sys.exit(1)
    return pos[0], pos[1], opts


def colour_by(channel):
    """Each body's shapes get an object colour from the channel; the materials read it."""
    helpers = [o for o in bpy.data.objects if "magsim_channels" in o.keys()]
    if not helpers:
        sys.exit("--color-by: the file has no channels (magsim-scene --gltf-channels)")
    names = list(helpers[0]["magsim_channels"])
    if channel not in names:
        sys.exit("--color-by: '%s' is not among the file's channels %s" % (channel, names))
    k = names.index(channel)
    values = {h.parent.name: h.scale[k] for h in helpers}
    top = max(values.values()) or 1.0
    cold, hot = Vector((0.05, 0.15, 0.6)), Vector((1.0, 0.45, 0.05))
    for body in (o for o in bpy.data.objects if "magsim_body" in o.keys()):
        x = values.get(body.name, 0.0) / top
        c = cold.lerp(hot, x)
        for child in body.children:
            if child.type == "MESH":
                child.color = (c.x, c.y, c.z, 1.0)
    for mat in bpy.data.materials:
        if mat.name == "ground" or not mat.use_nodes:
            continue
        tree = mat.node_tree
        bsdf = next((n for n in tree.nodes if n.type == "BSDF_PRINCIPLED"), None)
        if bsdf is not None:
            info = tree.nodes.new("ShaderNodeObjectInfo")
            tree.links.new(info.outputs["Color"], bsdf.inputs["Base Color"])
            bsdf.inputs["Metallic"].default_value = 0.0


def main():
    glb, out, opts = parse_args()
    fps = float(opts["--fps"])
    width, height = (int(x) for x in opts["--size"].split("x"))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = max(1, round(fps))
    bpy.ops.import_scene.gltf(filepath=glb, import_shading="SMOOTH")

    # the moment: --time, else the last key of any animated object
    last = 0.0
    for a in bpy.data.actions:
        last = max(last, a.frame_range[1])
    frame = float(opts["--time"]) * scene.render.fps if opts["--time"] is not None else last
    scene.frame_set(int(math.floor(frame)), subframe=frame - math.floor(frame))
    if opts["--color-by"]:
        colour_by(opts["--color-by"])

    cams = [o for o in bpy.data.objects if o.type == "CAMERA"]
    if not cams:
        sys.exit("the file has no camera")
    scene.camera = cams[0]
    # the preview renderer's light comes from (0.35, -0.45, 1) and its background is pale blue
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 3.0
    sun.data.angle = math.radians(3)
    sun.rotation_mode = "QUATERNION"
    sun.rotation_quaternion = Vector((0.35, -0.45, 1.0)).normalized().to_track_quat("Z", "Y")
    scene.collection.objects.link(sun)
    world = bpy.data.worlds.new("background")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.93, 0.95, 0.98, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = int(opts["--samples"])
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.render.filepath = out
    scene.render.image_settings.file_format = "JPEG" if out.lower().endswith((".jpg", ".jpeg")) else "PNG"
    bpy.ops.render.render(write_still=True)
    print("blender_render: %s at frame %.3f (t = %.4f s)" % (out, frame, frame / scene.render.fps), flush=True)


if __name__ == "__main__":
    main()
