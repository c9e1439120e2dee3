# Cycles 3.4 on tests/test_subsurface.c's sphere (docs/subsurface.md, "Against Cycles"):
# a unit sphere of a Principled BSDF with Random Walk subsurface (weight 1, colour C,
# radius R, ior 1.4, roughness 0) under a white world, seen as clpt's SPHERE_SCENE sees
# it (2.2 away, 30 degrees vertical, filling the view); prints the image's mean.
#   blender -b --factory-startup -P tools/cycles_subsurface.py -- 0.5,0.5,0.5 0.1,0.1,0.1 256 /tmp/out
# A reference beside the project, as ../shared/peers' scripts; not run by make.
import bpy, sys, json
import numpy as np
argv = sys.argv[sys.argv.index("--") + 1:]
color = [float(x) for x in argv[0].split(",")]
radius = [float(x) for x in argv[1].split(",")]
spp = int(argv[2]); out = argv[3]
bpy.ops.wm.read_factory_settings(use_empty=True)
sc = bpy.context.scene
sc.render.engine = 'CYCLES'
sc.cycles.device = 'CPU'
sc.cycles.samples = spp
sc.cycles.use_denoising = False
sc.cycles.max_bounces = 64; sc.cycles.diffuse_bounces = 64; sc.cycles.glossy_bounces = 64
sc.cycles.transmission_bounces = 64; sc.cycles.transparent_max_bounces = 64
sc.cycles.sample_clamp_direct = 0; sc.cycles.sample_clamp_indirect = 0
sc.cycles.filter_width = 0.01
sc.render.resolution_x = 32; sc.render.resolution_y = 32
sc.view_settings.view_transform = 'Standard'
world = bpy.data.worlds.new("w"); sc.world = world; world.use_nodes = True
world.node_tree.nodes["Background"].inputs[0].default_value = (1, 1, 1, 1)
world.node_tree.nodes["Background"].inputs[1].default_value = 1.0
bpy.ops.mesh.primitive_uv_sphere_add(segments=256, ring_count=128, radius=1.0)
obj = bpy.context.object
bpy.ops.object.shade_smooth()
mat = bpy.data.materials.new("m"); mat.use_nodes = True
bsdf = mat.node_tree.nodes["Principled BSDF"]
bsdf.subsurface_method = 'RANDOM_WALK'
bsdf.inputs["Base Color"].default_value = (*color, 1)
bsdf.inputs["Subsurface"].default_value = 1.0
bsdf.inputs["Subsurface Color"].default_value = (*color, 1)
bsdf.inputs["Subsurface Radius"].default_value = radius
bsdf.inputs["Roughness"].default_value = 0.0
bsdf.inputs["Specular"].default_value = ((1.4 - 1) / (1.4 + 1)) ** 2 / 0.08  # F0 of ior 1.4
bsdf.inputs["Subsurface IOR"].default_value = 1.4
obj.data.materials.append(mat)
cam = bpy.data.cameras.new("c"); cam.angle = 30 * 3.14159265 / 180; cam.sensor_fit = 'VERTICAL'
co = bpy.data.objects.new("c", cam); sc.collection.objects.link(co); sc.camera = co
co.location = (0, -2.2, 0); co.rotation_euler = (3.14159265 / 2, 0, 0)
sc.render.image_settings.file_format = 'OPEN_EXR'; sc.render.image_settings.color_depth = '32'
sc.render.filepath = out + ".exr"
bpy.ops.render.render(write_still=True)
img = bpy.data.images.load(out + ".exr")
px = np.array(img.pixels[:]).reshape(32, 32, 4)[:, :, :3]
print("CYCLES_MEAN", json.dumps(px.mean(axis=(0, 1)).tolist()))
