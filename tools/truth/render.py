# render.py — the path-traced reference of the bundled head: Blender Cycles (Debian's blender 3.4), run by
# tools/truth/truth.sh as
#
#   blender -b --factory-startup --python tools/truth/render.py -- SCENE_DIR DATA_DIR ENV SAMPLES OUT_DIR [SEEDS]
#
# SCENE_DIR: rouge-truth-scene's output (scene.json: rouge's cameras, region table; env_ENV.hdr: the
# environment turned and scaled as rouge sees it; splats.f32: the splats' regions) and sss_calibrate.py's
# (sss.json: the subsurface radius that scatters like rouge's skin profile).
# DATA_DIR: ../shared/data/leeperrysmith (head_mesh.ply, color.png, normal.png: what face.rsf was made from).
# SEEDS (default 1): each view is the mean of that many independent renders (Cycles seeds 1..SEEDS) of SAMPLES
# samples a pixel. Adaptive sampling stops a pixel at its noise threshold, so one render of twice the samples
# leaves most of the skin as noisy as before; the mean of two independent ones halves every pixel's variance.
# Writes OUT_DIR/ENV_VIEW.rtf for every view (the uncompressed fixture, tests/fixtures/truth/README.md); with
# TRUTH_PASSES=1 in the environment also OUT_DIR/ENV_VIEW_passes.npz, Cycles' light passes (DiffDir, DiffInd,
# DiffCol, GlossDir, GlossInd, GlossCol: premultiplied RGBA, rows from the top) and its ambient occlusion (AO,
# cosine-weighted, unbounded distance), to tell which part of the light differs from rouge's.
#
# The scene: the mesh in rouge's model coordinates (+y up, the face towards +z; Blender's own up axis plays no
# part), its vertex normals perturbed by the tangent-space normal map as the splats' were; a Principled BSDF
# with random-walk subsurface scattering: albedo = color.png, radius = the one that carries as much light
# past a shadow's edge as the skin profile (sss.json), F0 and roughness per region from the .rsf's region
# table; the world is the environment map looked up with the env frame's own mapping (docs/env.md), not
# Blender's.
import json
import math
import os
import struct
import sys

import bpy
import numpy as np
from mathutils import Matrix
from mathutils.kdtree import KDTree

argv = sys.argv[sys.argv.index("--") + 1:]
scene_dir, data_dir, env_name, samples, out_dir = argv[0], argv[1], argv[2], int(argv[3]), argv[4]
seeds = int(argv[5]) if len(argv) > 5 else 1
S = json.load(open(os.path.join(scene_dir, "scene.json")))
SSS = json.load(open(os.path.join(scene_dir, "sss.json")))  # sss_calibrate.py
size = S["size"]
env = next(e for e in S["envs"] if e["name"] == env_name)
F0_SKIN = 0.028          # skin, n = 1.4 (rouge's RS_F0_SKIN)
PASSES = ("DiffDir", "DiffInd", "DiffCol", "GlossDir", "GlossInd", "GlossCol", "AO") \
    if os.environ.get("TRUTH_PASSES") == "1" else ()

# Label values of the fixture's label plane (tests/test_truth.c reads them).
LABEL_REGION0 = 1        # 1 + region index of the .rsf table (nearest splat)
LABEL_EARS = 16
LABEL_UNDER_CHIN = 17
LABEL_CONTOUR = 128      # bit: the contour band


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    head = data[:end].decode("ascii").split("\n")
    nv = next(int(l.split()[2]) for l in head if l.startswith("element vertex"))
    nf = next(int(l.split()[2]) for l in head if l.startswith("element face"))
    props = [l.split()[2] for l in head if l.startswith("property float")]
    if props != ["x", "y", "z", "nx", "ny", "nz", "s", "t"]:
        sys.exit("render.py: %s: unexpected vertex layout %s" % (path, props))
    v = np.frombuffer(data, "<f4", nv * 8, end).reshape(nv, 8)
    f = np.frombuffer(data, np.dtype([("n", "u1"), ("i", "<i4", 3)]), nf, end + nv * 32)
    if np.any(f["n"] != 3):
        sys.exit("render.py: %s: faces are not all triangles" % path)
    return v, f["i"]


def build_mesh(splat_tree, splat_region):
    v, tris = read_ply(os.path.join(data_dir, "head_mesh.ply"))
    me = bpy.data.meshes.new("head")
    me.from_pydata(v[:, :3].tolist(), [], tris.tolist())
    me.update()
    uv = me.uv_layers.new(name="uv")
    loop_v = np.zeros(len(me.loops), np.int32)
    me.loops.foreach_get("vertex_index", loop_v)
    uv.data.foreach_set("uv", v[loop_v][:, 6:8].ravel())   # t = 0 is the image's bottom row, as in Blender
    me.polygons.foreach_set("use_smooth", np.ones(len(me.polygons), bool))
    me.use_auto_smooth = True
    me.normals_split_custom_set_from_vertices(v[:, 3:6].tolist())
    # Per-vertex specular parameters from the nearest splat's region.
    regions = S["regions"]
    rho_other = regions[0]["rho_s"]
    spec = np.zeros((len(v), 4), np.float32)
    for i, p in enumerate(v[:, :3]):
        r = regions[splat_region[splat_tree.find(p)[1]]]
        # Principled: F0 = 0.08 specular; GGX alpha = roughness^2 ~ Beckmann m.
        spec[i] = (F0_SKIN * r["rho_s"] / rho_other / 0.08, math.sqrt(r["m"]), 0.0, 1.0)
    attr = me.color_attributes.new("spec", "FLOAT_COLOR", "POINT")
    attr.data.foreach_set("color", spec.ravel())
    ob = bpy.data.objects.new("head", me)
    bpy.context.scene.collection.objects.link(ob)
    ob.data.materials.append(skin_material())
    return ob


def image(path, colorspace):
    im = bpy.data.images.load(path)
    im.colorspace_settings.name = colorspace
    return im


def skin_material():
    mat = bpy.data.materials.new("skin")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    bsdf = nt.nodes.new("ShaderNodeBsdfPrincipled")
    col = nt.nodes.new("ShaderNodeTexImage")
    col.image = image(os.path.join(data_dir, "color.png"), "sRGB")
    nrm = nt.nodes.new("ShaderNodeTexImage")
    nrm.image = image(os.path.join(data_dir, "normal.png"), "Non-Color")
    nmap = nt.nodes.new("ShaderNodeNormalMap")
    nmap.space = "TANGENT"
    nmap.uv_map = "uv"
    attr = nt.nodes.new("ShaderNodeAttribute")
    attr.attribute_name = "spec"
    sep = nt.nodes.new("ShaderNodeSeparateColor")
    nt.links.new(col.outputs["Color"], bsdf.inputs["Base Color"])
    nt.links.new(col.outputs["Color"], bsdf.inputs["Subsurface Color"])
    nt.links.new(nrm.outputs["Color"], nmap.inputs["Color"])
    nt.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    nt.links.new(attr.outputs["Color"], sep.inputs["Color"])
    nt.links.new(sep.outputs[0], bsdf.inputs["Specular"])
    nt.links.new(sep.outputs[1], bsdf.inputs["Roughness"])
    nt.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    bsdf.distribution = "GGX"
    bsdf.subsurface_method = "RANDOM_WALK"
    bsdf.inputs["Subsurface"].default_value = 1.0   # full subsurface; also the radius' multiplier
    mm = S["mm_per_unit"]
    bsdf.inputs["Subsurface Radius"].default_value = [r / mm for r in SSS["radius_mm"]]
    bsdf.inputs["Subsurface IOR"].default_value = 1.4
    bsdf.inputs["Subsurface Anisotropy"].default_value = 0.0
    bsdf.inputs["Sheen"].default_value = 0.0
    bsdf.inputs["Clearcoat"].default_value = 0.0
    bsdf.inputs["Specular Tint"].default_value = 0.0
    return mat


def albedo_material():
    """The albedo alone, as emission seen by the camera: the fixture's albedo plane (Cycles' diffuse-colour
    pass counts a subsurface Principled BSDF's colour twice)."""
    mat = bpy.data.materials.new("albedo")
    mat.use_nodes = True
    nt = mat.node_tree
    nt.nodes.clear()
    col = nt.nodes.new("ShaderNodeTexImage")
    col.image = bpy.data.images["color.png"]
    em = nt.nodes.new("ShaderNodeEmission")
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(col.outputs["Color"], em.inputs["Color"])
    nt.links.new(em.outputs["Emission"], out.inputs["Surface"])
    return mat


def build_world():
    im = image(os.path.join(scene_dir, env["map"]), "Linear")
    world = bpy.data.worlds.new("env")
    world.use_nodes = True
    nt = world.node_tree
    nt.nodes.clear()
    tc = nt.nodes.new("ShaderNodeTexCoord")
    norm = nt.nodes.new("ShaderNodeVectorMath")
    norm.operation = "NORMALIZE"
    sep = nt.nodes.new("ShaderNodeSeparateXYZ")
    # The env frame's mapping: phi = atan2(x, z) = 2 pi (u - 1/2), theta = acos(y) = pi v (v from the top).
    phi = nt.nodes.new("ShaderNodeMath")
    phi.operation = "ARCTAN2"
    u = nt.nodes.new("ShaderNodeMath")
    u.operation = "MULTIPLY_ADD"
    u.inputs[1].default_value = 1.0 / (2 * math.pi)
    u.inputs[2].default_value = 0.5
    theta = nt.nodes.new("ShaderNodeMath")
    theta.operation = "ARCCOSINE"
    v = nt.nodes.new("ShaderNodeMath")
    v.operation = "MULTIPLY_ADD"
    v.inputs[1].default_value = -1.0 / math.pi     # Blender's v grows upwards
    v.inputs[2].default_value = 1.0
    comb = nt.nodes.new("ShaderNodeCombineXYZ")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image = im
    tex.interpolation = "Linear"
    tex.extension = "REPEAT"
    bg = nt.nodes.new("ShaderNodeBackground")
    out = nt.nodes.new("ShaderNodeOutputWorld")
    L = nt.links
    L.new(tc.outputs["Generated"], norm.inputs[0])
    L.new(norm.outputs["Vector"], sep.inputs[0])
    L.new(sep.outputs["X"], phi.inputs[0])
    L.new(sep.outputs["Z"], phi.inputs[1])
    L.new(phi.outputs[0], u.inputs[0])
    L.new(sep.outputs["Y"], theta.inputs[0])
    L.new(theta.outputs[0], v.inputs[0])
    L.new(u.outputs[0], comb.inputs["X"])
    L.new(v.outputs[0], comb.inputs["Y"])
    L.new(comb.outputs[0], tex.inputs["Vector"])
    L.new(tex.outputs["Color"], bg.inputs["Color"])
    L.new(bg.outputs["Background"], out.inputs["Surface"])
    world.cycles.sampling_method = "MANUAL"
    world.cycles.sample_map_resolution = 2048   # the sun is ~1 texel of the 1024-wide map
    bpy.context.scene.world = world


def setup_render():
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    c = sc.cycles
    c.device = "CPU"
    c.samples = samples
    c.use_adaptive_sampling = True
    c.adaptive_threshold = 0.005
    c.use_denoising = False          # Debian's build has no denoiser; the test blurs by 1 px
    c.max_bounces = 16
    c.diffuse_bounces = 8
    c.glossy_bounces = 8
    c.transmission_bounces = 8
    c.transparent_max_bounces = 8
    c.caustics_reflective = False
    c.caustics_refractive = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.pixel_filter_type = "BOX"      # each pixel the mean over its own area
    c.filter_width = 1.0
    sc.render.threads_mode = "FIXED"
    sc.render.threads = 2
    sc.render.resolution_x = sc.render.resolution_y = size
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = True
    sc.view_settings.view_transform = "Standard"
    vl = sc.view_layers[0]
    vl.use_pass_position = True
    vl.use_pass_normal = True
    vl.use_pass_z = True
    # Every pass to its own float EXR through the compositor.
    sc.use_nodes = True
    nt = sc.node_tree
    nt.nodes.clear()
    rl = nt.nodes.new("CompositorNodeRLayers")
    fo = nt.nodes.new("CompositorNodeOutputFile")
    fo.base_path = out_dir
    fo.format.file_format = "OPEN_EXR"
    fo.format.color_depth = "32"
    fo.format.color_mode = "RGBA"
    fo.file_slots.clear()
    if PASSES:
        for p in ("diffuse_direct", "diffuse_indirect", "diffuse_color", "glossy_direct", "glossy_indirect",
                  "glossy_color", "ambient_occlusion"):
            setattr(vl, "use_pass_" + p, True)
        sc.world.light_settings.distance = 1e4   # the whole sky, as rouge-pack's occlusion
    for name in ("Image", "Position", "Normal", "Depth") + PASSES:
        fo.file_slots.new(name)
        nt.links.new(rl.outputs[name], fo.inputs[name])
    return fo


def read_exr(path):
    im = bpy.data.images.load(path)          # float EXR: scene-linear as written ("Linear")
    a = np.empty(im.size[0] * im.size[1] * 4, np.float32)
    im.pixels.foreach_get(a)
    bpy.data.images.remove(im)
    return a.reshape(size, size, 4)[::-1]        # rows from the top, as rouge reads its frames


def unpremultiply(img):
    """Film is transparent: passes are premultiplied; the fixture keeps the surface's own values."""
    a = img[..., 3:4]
    return np.where(a > 1e-4, img[..., :3] / np.maximum(a, 1e-4), 0.0)


def set_camera(view):
    cam = bpy.data.cameras.new("cam")
    P = view["proj"]                              # column-major GL matrices
    cam.sensor_fit = "VERTICAL"
    cam.angle_y = 2 * math.atan(1.0 / P[5])
    near = P[14] / (P[10] - 1.0)
    far = P[14] / (P[10] + 1.0)
    cam.clip_start, cam.clip_end = near * 0.5, far * 2.0
    ob = bpy.data.objects.get("cam") or bpy.data.objects.new("cam", cam)
    ob.data = cam
    if ob.name not in bpy.context.scene.collection.objects:
        bpy.context.scene.collection.objects.link(ob)
    Vm = view["view"]
    V = Matrix([[Vm[c * 4 + r] for c in range(4)] for r in range(4)])
    # A GL eye space is Blender's camera space (looks along -z, +y up): the camera's world matrix is V^-1.
    ob.matrix_world = V.inverted()
    bpy.context.scene.camera = ob


def erode(mask, n):
    m = mask.copy()
    for _ in range(n):
        e = m.copy()
        e[1:, :] &= m[:-1, :]
        e[:-1, :] &= m[1:, :]
        e[:, 1:] &= m[:, :-1]
        e[:, :-1] &= m[:, 1:]
        m = e
    return m


def labels(alpha, pos, nrm, depth, splat_tree, splat_region):
    c = S["centre"]
    face = alpha >= 0.5
    lab = np.zeros((size, size), np.uint8)
    ys, xs = np.nonzero(face)
    for y, x in zip(ys, xs):
        co, idx, dist = splat_tree.find(pos[y, x, :3])
        lab[y, x] = LABEL_REGION0 + splat_region[idx] if dist < 0.1 else LABEL_REGION0
    # Geometry in the face frame (model units, +y up, the face towards +z; centre on the nose's plane).
    P = pos[..., :3]
    dx, yy, zz = np.abs(P[..., 0] - c[0]), P[..., 1], P[..., 2]
    menton = 3.97 - S["face_height"]              # 3.97: the scalp's highest point (head_mesh.ply's bbox)
    # Ears: what sticks out beyond the skull (half-width 1.25-1.40 there) between lobe and top, around z 0.
    ears = face & (dx > 1.40) & (yy > 0.5) & (yy < 1.95) & (zz > -0.55) & (zz < 0.6)
    chin = face & (dx < 1.0) & (yy < menton + 0.15) & (yy > menton - 0.9) & (zz > 0.2) & (nrm[..., 1] < 0.2)
    lab[ears] = LABEL_EARS
    lab[chin] = LABEL_UNDER_CHIN
    # Contour band: 3 px inside the silhouette, and 3 px on the near side of depth steps over 10 mm
    # (ear rims over the head, the nose over the cheek, the jaw over the neck).
    band = face & ~erode(face, 3)
    d = np.where(face, depth, np.inf)
    step = 10.0 / S["mm_per_unit"]
    near_edge = np.zeros_like(face)
    for oy in range(-3, 4):
        for ox in range(-3, 4):
            sh = np.full_like(d, np.inf)
            ys0, ys1 = max(oy, 0), size + min(oy, 0)
            xs0, xs1 = max(ox, 0), size + min(ox, 0)
            sh[ys0 - oy:ys1 - oy, xs0 - ox:xs1 - ox] = d[ys0:ys1, xs0:xs1]
            near_edge |= face & np.isfinite(sh) & (sh > d + step)
    lab[band | near_edge] |= LABEL_CONTOUR
    return lab


def write_fixture(path, view, rgb, alb, alpha, lab):
    head = struct.pack("<8sII16s16sffffI", b"RSTRUTH1", size, size, env_name.encode(), view["name"].encode(),
                       view["yaw"], view["pitch"], env["scale"], float(samples * seeds), 0)
    with open(path, "wb") as f:
        f.write(head)
        f.write(rgb.astype("<f2").tobytes())
        f.write(alb.astype("<f2").tobytes())
        f.write(np.clip(np.rint(alpha * 255), 0, 255).astype(np.uint8).tobytes())
        f.write(lab.tobytes())


def main():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    sp = np.fromfile(os.path.join(scene_dir, "splats.f32"), "<f4").reshape(-1, 4)
    tree = KDTree(len(sp))
    for i, p in enumerate(sp[:, :3]):
        tree.insert(p, i)
    tree.balance()
    region = sp[:, 3].astype(np.int32)
    build_mesh(tree, region)
    build_world()
    albedo = albedo_material()
    fo = setup_render()
    for view in S["views"]:
        set_camera(view)
        prefix = "%s_%s_" % (env_name, view["name"])
        for slot in fo.file_slots:
            slot.path = prefix + slot.path.split("_")[-1]
        sc = bpy.context.scene
        sc.frame_set(1)
        vl = sc.view_layers[0]
        vl.material_override = None
        sc.cycles.samples = samples
        px = {}
        for seed in range(1, seeds + 1):
            sc.cycles.seed = seed
            bpy.ops.render.render(write_still=False)
            # The light (premultiplied) is averaged over the seeds; the geometry is the first render's.
            for n in ("Image",) + PASSES + (("Position", "Normal", "Depth") if seed == 1 else ()):
                a = read_exr(os.path.join(out_dir, "%s%s0001.exr" % (prefix, n)))
                px[n] = px[n] + a if seed > 1 and n in ("Image",) + PASSES else a
        for n in ("Image",) + PASSES:
            px[n] /= seeds
        if PASSES:
            np.savez_compressed(os.path.join(out_dir, "%s_%s_passes.npz" % (env_name, view["name"])),
                                **{n: px[n] for n in PASSES})
        # The albedo: the same camera, the emission-only material, 16 samples (pixel coverage only).
        vl.material_override = albedo
        sc.cycles.samples = 16
        bpy.ops.render.render(write_still=False)
        px["Albedo"] = read_exr(os.path.join(out_dir, "%sImage0001.exr" % prefix))
        alpha, rgb = px["Image"][..., 3], unpremultiply(px["Image"])
        lab = labels(alpha, px["Position"], px["Normal"], px["Depth"][..., 0], tree, region)
        write_fixture(os.path.join(out_dir, "%s_%s.rtf" % (env_name, view["name"])), view, rgb,
                      unpremultiply(px["Albedo"]), alpha, lab)
        print("render.py: %s %s done" % (env_name, view["name"]), flush=True)


main()
