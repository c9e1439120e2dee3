# Blender-side half of tools/xcheck/xcheck.py: renders a list of glTF scenes with Cycles,
# each imported by Blender's own glTF importer, in one Blender process (its start-up
# costs seconds).
#
#   blender -b --factory-startup --python-exit-code 1 -P cycles_render.py -- JOBS.json
#
# JOBS.json is a list of jobs: {"gltf", "out" (base name), "width", "height", "spp",
# "seed", "bounces" (Cycles' max_bounces), "background": {"kind": "white" | "black" |
# "env", "map", "rotz"}, "override": null | "diffuse:R,G,B"}. Each writes OUT.npy (H x W
# x 3 float32, linear, top row first) and OUT.json (the lights and Principled BSDFs as
# imported, the image mean, the render's seconds). An optional "threads" sets Cycles'
# render threads (default 2). "diffuse:R,G,B" makes every surface a Lambertian Diffuse
# BSDF, fed by the normal map the importer made, if any.
#
# Conventions (matched with clpt; ../shared/peers/README.md found them first):
# - punctual lights: the importer gives lights a 0.25 m radius and suns a 0.53 degree
#   angle; glTF's lights are points, so both are set to 0.
# - environment map: Generated coordinates turned +90 degrees about Z into an
#   Environment Texture with Closest lookup equal clpt's `background { map }`.
# - path tracing, no denoising, no clamping, no light threshold, box filter 1 pixel,
#   "Standard" view transform, 32-bit float EXR read back.
import json
import math
import sys
import time

import bpy
import numpy as np

if not hasattr(np, "bool"):
    np.bool = bool   # Blender 3.4's importer uses np.bool, which numpy 1.24 removed


def lights_points(sc, info):
    for o in sc.objects:
        if o.type != "LIGHT":
            continue
        L = o.data
        d = {"name": o.name, "type": L.type, "energy": L.energy, "color": list(L.color)}
        if L.type == "SUN":
            L.angle = 0.0
        else:
            L.shadow_soft_size = 0.0
        if L.type == "SPOT":
            d["spot_size_deg"] = math.degrees(L.spot_size)
            d["spot_blend"] = L.spot_blend
        info["lights"].append(d)


def diffuse_node(nt, rgb):
    dn = nt.nodes.new("ShaderNodeBsdfDiffuse")
    dn.inputs["Color"].default_value = (*rgb, 1.0)
    dn.inputs["Roughness"].default_value = 0.0
    return dn


def override_diffuse(sc, rgb):
    """Every mesh's surface becomes one Diffuse BSDF (Lambert: roughness 0) of colour rgb.
    An imported material keeps its nodes, and the normal map the importer linked to its
    Principled BSDF's Normal (a Normal Map node: glTF's normalTexture) now feeds the
    Diffuse BSDF's; a mesh slot with no node material gets a plain one."""
    plain, done = None, set()
    for o in sc.objects:
        if o.type != "MESH":
            continue
        for slot in o.material_slots:
            m = slot.material
            if m is None or not m.use_nodes:
                if plain is None:
                    plain = bpy.data.materials.new("xcheck-diffuse")
                    plain.use_nodes = True
                    nt = plain.node_tree
                    nt.nodes.remove(nt.nodes["Principled BSDF"])
                    nt.links.new(diffuse_node(nt, rgb).outputs["BSDF"], nt.nodes["Material Output"].inputs["Surface"])
                slot.material = plain
                continue
            if m.name in done:
                continue
            done.add(m.name)
            nt = m.node_tree
            dn = diffuse_node(nt, rgb)
            for n in nt.nodes:
                if n.type == "BSDF_PRINCIPLED" and n.inputs["Normal"].is_linked:
                    nt.links.new(n.inputs["Normal"].links[0].from_socket, dn.inputs["Normal"])
            out = [n for n in nt.nodes if n.type == "OUTPUT_MATERIAL"]
            nt.links.new(dn.outputs["BSDF"], out[0].inputs["Surface"])


def world(sc, bgd):
    w = bpy.data.worlds.new("xcheck")
    sc.world = w
    w.use_nodes = True
    nt = w.node_tree
    bg = nt.nodes["Background"]
    kind = bgd["kind"]
    if kind == "env":
        tc = nt.nodes.new("ShaderNodeTexCoord")
        mp = nt.nodes.new("ShaderNodeMapping")
        mp.vector_type = "POINT"
        mp.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(bgd.get("rotz", 90.0)))
        et = nt.nodes.new("ShaderNodeTexEnvironment")
        et.image = bpy.data.images.load(bgd["map"])
        et.interpolation = "Closest"
        nt.links.new(tc.outputs["Generated"], mp.inputs["Vector"])
        nt.links.new(mp.outputs["Vector"], et.inputs["Vector"])
        nt.links.new(et.outputs["Color"], bg.inputs["Color"])
        bg.inputs["Strength"].default_value = 1.0
        w.cycles.sampling_method = "MANUAL"
        w.cycles.sample_map_resolution = 1024
    elif kind == "white":
        bg.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        bg.inputs["Strength"].default_value = 1.0
    else:
        bg.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        bg.inputs["Strength"].default_value = 0.0


def settings(sc, job):
    sc.render.engine = "CYCLES"
    cy = sc.cycles
    cy.device = "CPU"
    cy.samples = job["spp"]
    cy.use_adaptive_sampling = False
    cy.use_denoising = False
    b = job["bounces"]
    cy.max_bounces = cy.diffuse_bounces = cy.glossy_bounces = b
    cy.transmission_bounces = cy.volume_bounces = cy.transparent_max_bounces = b
    cy.caustics_reflective = cy.caustics_refractive = True
    cy.blur_glossy = 0.0
    cy.sample_clamp_direct = cy.sample_clamp_indirect = 0.0
    cy.light_sampling_threshold = 0.0
    cy.pixel_filter_type = "BOX"
    cy.filter_width = 1.0
    cy.seed = job["seed"]
    sc.render.threads_mode = "FIXED"
    sc.render.threads = job.get("threads", 2)
    sc.render.resolution_x = job["width"]
    sc.render.resolution_y = job["height"]
    sc.render.resolution_percentage = 100
    sc.render.film_transparent = False
    sc.view_settings.view_transform = "Standard"
    sc.view_settings.look = "None"
    sc.view_settings.exposure = 0.0
    sc.view_settings.gamma = 1.0
    s = sc.render.image_settings
    s.file_format = "OPEN_EXR"
    s.color_depth = "32"
    s.exr_codec = "ZIP"


def render(job):
    bpy.ops.wm.read_factory_settings(use_empty=True)
    bpy.ops.import_scene.gltf(filepath=job["gltf"])
    sc = bpy.context.scene
    info = {"lights": [], "materials": []}
    lights_points(sc, info)
    cams = [o for o in sc.objects if o.type == "CAMERA"]
    sc.camera = cams[0]
    for m in bpy.data.materials:
        if m.use_nodes:
            for n in m.node_tree.nodes:
                if n.type == "BSDF_PRINCIPLED":
                    info["materials"].append({
                        "name": m.name,
                        "inputs": {i.name: (list(i.default_value) if hasattr(i.default_value, "__len__")
                                            else i.default_value) for i in n.inputs
                                   if hasattr(i, "default_value") and not i.is_linked and i.name != "Normal"},
                        "linked": [i.name for i in n.inputs if i.is_linked]})
    ov = job.get("override")
    if ov and ov.startswith("diffuse:"):
        override_diffuse(sc, [float(x) for x in ov[8:].split(",")])
    world(sc, job["background"])
    settings(sc, job)
    out = job["out"]
    sc.render.filepath = out + ".exr"
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    info["render_s"] = time.perf_counter() - t0   # scene sync, BVH build, render, EXR write
    img = bpy.data.images.load(out + ".exr")
    W, H = job["width"], job["height"]
    px = np.array(img.pixels[:], dtype=np.float32).reshape(H, W, 4)[::-1, :, :3]
    np.save(out + ".npy", np.ascontiguousarray(px))
    info["mean"] = [float(x) for x in px.reshape(-1, 3).mean(0)]
    with open(out + ".json", "w") as f:
        json.dump(info, f, indent=1)


def main():
    jobs = json.load(open(sys.argv[sys.argv.index("--") + 1]))
    for job in jobs:
        render(job)
        print("XCHECK_CYCLES_DONE", job["out"], flush=True)


main()
