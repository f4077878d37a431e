# sss_calibrate.py — the Cycles subsurface radius that scatters like rouge's skin profile (issue 22), run by
# tools/truth/truth.sh before the renders as
#
#   blender -b --factory-startup --python tools/truth/sss_calibrate.py -- SCENE_DIR DATA_DIR SAMPLES
#
# Reads SCENE_DIR/scene.json's sss_edge_mm (per channel, what the d'Eon profile carries into a shadow: behind
# a straight shadow edge on a flat surface, the integral of the lit fraction over the shadow side, mm) and
# DATA_DIR/color.png (the skin's mean albedo); writes SCENE_DIR/sss.json with the radius render.py uses.
#
# Why: Cycles' random walk takes its radius as the mean free path of a medium whose single-scattering albedo
# it inverts from the surface colour, so the light it carries past an edge is neither the radius nor the
# profile's mean scattering distance: at skin's albedo a radius of 1.12 mm (the profile's mean radius, the
# mapping the fixtures used before) carried a third of what the profile carries in red. The walk has no
# length of its own, so what it carries scales with the radius at a given albedo: one render of a lit slab
# behind a straight shadow edge per step, the radius scaled by target / measured, twice (the second step
# corrects the first one's noise), and a last render reports what the chosen radius carries.
import json
import os
import sys

import bpy
import numpy as np

argv = sys.argv[sys.argv.index("--") + 1:]
scene_dir, data_dir, samples = argv[0], argv[1], int(argv[2])
S = json.load(open(os.path.join(scene_dir, "scene.json")))
target = np.array(S["sss_edge_mm"], float)
WIDTH_MM, PIXELS = 24.0, 960        # the strip across the edge: the red tail has settled by 12 mm


def mean_albedo():
    """The scan's mean linear colour over its texture's painted texels (the atlas' padding is black)."""
    im = bpy.data.images.load(os.path.join(data_dir, "color.png"))
    a = np.empty(im.size[0] * im.size[1] * 4, np.float32)
    im.pixels.foreach_get(a)          # the file's own sRGB values (a byte image is not decoded)
    bpy.data.images.remove(im)
    a = a.reshape(-1, 4)[:, :3]
    a = a[a.max(1) > 0.1]
    return np.where(a <= 0.04045, a / 12.92, ((a + 0.055) / 1.055) ** 2.4).mean(0)


def build(albedo):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sc = bpy.context.scene
    # A slab 200 x 200 x 20 mm (1 unit = 1 mm here), top face at z = 0.
    bpy.ops.mesh.primitive_cube_add(size=1, location=(0, 0, -10))
    slab = bpy.context.object
    slab.scale = (200, 200, 20)
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
    mat = bpy.data.materials.new("skin")
    mat.use_nodes = True
    b = mat.node_tree.nodes["Principled BSDF"]
    b.subsurface_method = "RANDOM_WALK"
    b.inputs["Base Color"].default_value = list(albedo) + [1]
    b.inputs["Subsurface Color"].default_value = list(albedo) + [1]
    b.inputs["Subsurface"].default_value = 1.0
    b.inputs["Subsurface IOR"].default_value = 1.4      # as render.py
    b.inputs["Specular"].default_value = 0.0
    b.inputs["Sheen"].default_value = 0.0
    slab.data.materials.append(mat)
    # The shadow's edge: a plane over x < 0 just above the slab that only the sun's shadow rays see.
    bpy.ops.mesh.primitive_plane_add(size=1, location=(-100, 0, 0.3))
    bl = bpy.context.object
    bl.scale = (200, 400, 1)
    for v in ("visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume_scatter"):
        setattr(bl, v, False)
    bpy.ops.object.light_add(type="SUN", location=(0, 0, 100))
    bpy.context.object.data.angle = 0.0
    world = bpy.data.worlds.new("dark")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.0
    sc.world = world
    bpy.ops.object.camera_add(location=(0, 0, 50))
    cam = bpy.context.object
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = WIDTH_MM
    sc.camera = cam
    sc.render.engine = "CYCLES"
    c = sc.cycles
    c.device = "CPU"
    c.samples = samples
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = 1
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
    sc.render.threads_mode = "FIXED"
    sc.render.threads = 2
    sc.render.resolution_x = sc.render.resolution_y = PIXELS
    sc.render.resolution_percentage = 100
    sc.render.use_border = True                     # a strip of 20 rows across the edge
    sc.render.use_crop_to_border = True
    sc.render.border_min_x, sc.render.border_max_x = 0.0, 1.0
    sc.render.border_min_y, sc.render.border_max_y = 0.49, 0.51
    sc.view_settings.view_transform = "Standard"
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    return b


def carried(bsdf, radius):
    """Render the edge with this radius; per channel, the lit fraction integrated over the shadow side, mm."""
    bsdf.inputs["Subsurface Radius"].default_value = list(radius)
    sc = bpy.context.scene
    sc.render.filepath = os.path.join(scene_dir, "sss_edge.exr")
    bpy.ops.render.render(write_still=True)
    im = bpy.data.images.load(sc.render.filepath)
    a = np.empty(im.size[0] * im.size[1] * 4, np.float32)
    im.pixels.foreach_get(a)
    w, h = im.size
    bpy.data.images.remove(im)
    s = a.reshape(h, w, 4)[:, :, :3].mean(0)
    dx = WIDTH_MM / w
    x = (np.arange(w) + 0.5) * dx - WIDTH_MM / 2
    lit, dark = s[-40:].mean(0), s[:40].mean(0)
    frac = (s - dark) / np.maximum(lit - dark, 1e-9)
    return (frac * (x < 0)[:, None]).sum(0) * dx


def main():
    albedo = mean_albedo()
    bsdf = build(albedo)
    radius = 8.0 * target          # about where it lands at skin's albedo
    for step in range(2):
        got = carried(bsdf, radius)
        print("sss_calibrate: step %d radius %s mm carries %s mm (target %s)" % (
            step, np.round(radius, 4), np.round(got, 4), np.round(target, 4)), flush=True)
        radius = radius * target / np.maximum(got, 1e-6)
    got = carried(bsdf, radius)
    print("sss_calibrate: radius %s mm carries %s mm (target %s) at albedo %s" % (
        np.round(radius, 4), np.round(got, 4), np.round(target, 4), np.round(albedo, 3)), flush=True)
    if np.any(np.abs(got / target - 1) > 0.1):
        raise SystemExit("sss_calibrate: the chosen radius misses the target by more than 10 %")
    with open(os.path.join(scene_dir, "sss.json"), "w") as f:
        json.dump({"radius_mm": radius.tolist(), "carries_mm": got.tolist(), "target_mm": target.tolist(),
                   "albedo": albedo.tolist(), "samples": samples}, f, indent=2)
    os.remove(os.path.join(scene_dir, "sss_edge.exr"))


main()
