#!/usr/bin/env python3
"""The peer benchmark's generated scenes (bench/peers.py): the same triangles, materials,
media, lights and camera written for clpt (a scene file and PLY meshes) and for Mitsuba 3
(a scene dict), from tools/xcheck's geometry, PLY writer and media (imported, not copied).

  envmat  an environment-lit still life under ../shared/envmaps/courtyard.hdr (lit by it
          and seen in reflections, not directly: see CAMERAS): a rough
          gold sphere (clpt `conductor metal Au`, Mitsuba `roughconductor` with the same
          eta and k), a rough glass sphere (GGX, ior 1.5) and a Lambertian sphere on a
          Lambertian floor: the materials both renderers model the same way (GGX with
          alpha = roughness^2; low roughness, where Mitsuba's separable Smith G and clpt's
          height-correlated one agree to a fraction of the noise)
  fog     a unit sphere of homogeneous fog (tools/xcheck's `medium`: sigma_a 0.5,
          sigma_s 1.5, g 0.5) behind a boundary that is no surface, beside a Lambertian
          sphere on a floor, under a square area light facing down
  smoke   the same with tools/xcheck's `medium-grid` (a 16^3 density grid, chromatic
          extinction) in the sphere

All are 256 x 256 (a quarter of the peers' scenes' pixels: their converged references
take minutes, not an hour, on two cores) with 8 bounces after the camera ray (Mitsuba's max_depth 9: it counts
the camera vertex), box filter, as the peers' own scenes.

usage (what bench/peers.py runs; Dr.Jit caches its kernels, so run once to warm up):
  peers_scenes.py mitsuba SCENE SPP OUT.pfm SEED VARIANT SAMPLER FOLDER
renders SCENE with Mitsuba from the PLY files in FOLDER (written by write_clpt) and prints
one JSON line: load_s (scene load and BVH build) and render_s.
"""
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, '..', 'tools', 'xcheck'))
import scenes as xscenes  # noqa: E402
import xcheck  # noqa: E402

SIZE = 256
DEPTH = 8                                   # clpt: bounces after the camera ray
# from, at, vertical fov: the media scenes use xcheck's floor camera; envmat looks down
# on a wider floor so that no pixel sees the map itself (a directly seen map measures
# the renderers' texture lookups, clpt's nearest against Mitsuba's bilinear, not the
# materials)
CAMERAS = {'envmat': ((0.0, 3.0, 4.5), (0.0, -0.5, 0.0), 40.0),
           'fog': ((0.0, 2.0, 6.0), (0.0, -0.5, 0.0), 35.0),
           'smoke': ((0.0, 2.0, 6.0), (0.0, -0.5, 0.0), 35.0)}
ENVMAP = os.path.abspath(os.path.join(HERE, '..', '..', 'shared', 'envmaps', 'courtyard.hdr'))
GREY = (0.5, 0.5, 0.5)
ORANGE = xscenes.ORANGE
# gold's complex index at 650, 550, 450 nm, as clpt's `metal Au` (docs/scene-format.md)
AU_ETA, AU_K = (0.1678, 0.3504, 1.5085), (3.1378, 2.7141, 1.8788)
LAMP_HALF, LAMP_Y, LAMP_RADIANCE = 0.75, 3.0, 12.0


def sphere(center, radius):
    p, n, uv, tan, idx = xcheck.uv_sphere()
    return (p * np.float32(radius) + np.array(center, np.float32), n, uv, tan, idx)


def floor(scale):
    """xcheck's floor (8 x 8 at y = -1) widened scale times in x and z."""
    p, n, uv, tan, idx = xcheck.floor_quad()
    return (p * np.array([scale, 1.0, scale], np.float32), n, uv, tan, idx)


def lamp():
    """A square facing down (its winding's normal is -y: clpt and Mitsuba emit on that side)."""
    h, y = LAMP_HALF, LAMP_Y
    p = np.array([[-h, y, -h], [h, y, -h], [h, y, h], [-h, y, h]], np.float32)
    n = np.tile(np.array([0, -1, 0], np.float32), (4, 1))
    uv = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32)
    tan = np.tile(np.array([1, 0, 0, 1], np.float32), (4, 1))
    return p, n, uv, tan, np.array([(0, 1, 2), (0, 2, 3)], np.uint32)


def _xcheck_medium(name):
    return next(s for s in xscenes.scene_list() if s['name'] == name)


def objects(scene):
    """[(name, geometry, clpt material body or None, clpt mesh keys, Mitsuba BSDF(mi), extra Mitsuba keys(mi))]"""
    ground = ('floor', floor(3.0 if scene == 'envmat' else 1.0), 'type diffuse albedo %g %g %g' % GREY, '',
             lambda mi: {'type': 'diffuse', 'reflectance': xscenes._rgb(GREY)}, None)
    if scene == 'envmat':
        return [ground,
                ('gold', sphere((-1.4, -0.4, 0.0), 0.6), 'type conductor metal Au roughness 0.2', '',
                 lambda mi: {'type': 'roughconductor', 'distribution': 'ggx', 'alpha': 0.04,
                             'eta': xscenes._rgb(AU_ETA), 'k': xscenes._rgb(AU_K)}, None),
                ('glass', sphere((0.0, -0.4, 0.0), 0.6), 'type dielectric ior 1.5 roughness 0.3', '',
                 lambda mi: {'type': 'roughdielectric', 'distribution': 'ggx', 'alpha': 0.09,
                             'int_ior': 1.5, 'ext_ior': 1.0}, None),
                ('diffuse', sphere((1.4, -0.4, 0.0), 0.6), 'type diffuse albedo %g %g %g' % ORANGE, '',
                 lambda mi: {'type': 'diffuse', 'reflectance': xscenes._rgb(ORANGE)}, None)]
    if scene in ('fog', 'smoke'):
        med = _xcheck_medium('medium' if scene == 'fog' else 'medium-grid')
        interior = med['mitsuba_interior']
        return [ground,
                ('diffuse', sphere((1.8, -0.5, 0.6), 0.5), 'type diffuse albedo %g %g %g' % ORANGE, '',
                 lambda mi: {'type': 'diffuse', 'reflectance': xscenes._rgb(ORANGE)}, None),
                # the medium's boundary: the unit sphere, where xcheck's grid lies ([-1, 1]^3)
                ('medium', xcheck.uv_sphere(), None, med['clpt_mesh'], lambda mi: {'type': 'null'},
                 lambda mi: {'interior': interior(mi) if callable(interior) else interior}),
                ('lamp', lamp(), 'type emissive radiance %g %g %g' % ((LAMP_RADIANCE,) * 3), '',
                 lambda mi: {'type': 'diffuse', 'reflectance': xscenes._rgb((0, 0, 0))},
                 lambda mi: {'emitter': {'type': 'area', 'radiance': xscenes._rgb((LAMP_RADIANCE,) * 3)}})]
    raise KeyError(scene)


def ply_path(folder, scene, name):
    return os.path.join(folder, '%s-%s.ply' % (scene, name))


def write_clpt(scene, folder, envmap=ENVMAP):
    """Writes SCENE's PLY files and clpt scene file into folder; returns the scene file's path."""
    cam_from, cam_at, fov = CAMERAS[scene]
    lines = ['# bench/peers_scenes.py: %s (generated; the PLY files beside it are the triangles '
             'Mitsuba reads too)' % scene,
             'image { width %d height %d spp 16 depth %d }' % (SIZE, SIZE, DEPTH),
             'camera { from %g %g %g at %g %g %g up 0 1 0 fov %g }' % (cam_from + cam_at + (fov,))]
    lines.append('background { map "%s" }' % envmap if scene == 'envmat' else 'background { color 0 0 0 }')
    if scene in ('fog', 'smoke'):
        med = _xcheck_medium('medium' if scene == 'fog' else 'medium-grid')
        lines.append('medium fog { %s }' % med['clpt_medium'])
    for name, geo, body, keys, _, _ in objects(scene):
        path = ply_path(folder, scene, name)
        xcheck.write_ply(path, geo)
        if body:
            lines.append('material %s { %s }' % (name, body))
        lines.append('mesh { file "%s" %s }' % (os.path.basename(path), keys or 'material ' + name))
    out = os.path.join(folder, scene + '.scene')
    with open(out, 'w') as f:
        f.write('\n'.join(lines) + '\n')
    return out


def mitsuba_dict(mi, scene, folder, spp, sampler, envmap=ENVMAP):
    cam_from, cam_at, fov = CAMERAS[scene]
    d = {'type': 'scene',
         'integrator': {'type': 'path' if scene == 'envmat' else 'volpath', 'max_depth': DEPTH + 1},
         'sensor': {'type': 'perspective', 'fov': fov, 'fov_axis': 'y',
                    'to_world': mi.ScalarTransform4f().look_at(origin=list(cam_from), target=list(cam_at),
                                                               up=[0, 1, 0]),
                    'film': {'type': 'hdrfilm', 'width': SIZE, 'height': SIZE, 'rfilter': {'type': 'box'},
                             'pixel_format': 'rgb'},
                    'sampler': {'type': sampler, 'sample_count': spp}}}
    if scene == 'envmat':
        d['env'] = {'type': 'envmap', 'filename': envmap}
    for name, _, _, _, bsdf, extra in objects(scene):
        shape = {'type': 'ply', 'filename': ply_path(folder, scene, name), 'bsdf': bsdf(mi), 'face_normals': False}
        if extra:
            shape.update(extra(mi))
        d[name] = shape
    return d


def mitsuba_main(argv):
    scene, spp, out, seed, variant, sampler, folder = argv
    spp, seed = int(spp), int(seed)
    import mitsuba as mi
    import drjit as dr
    mi.set_variant(variant)
    dr.set_thread_count(2)
    t0 = time.perf_counter()
    sc = mi.load_dict(mitsuba_dict(mi, scene, folder, spp, sampler))
    t1 = time.perf_counter()
    img = mi.render(sc, spp=spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    t2 = time.perf_counter()
    a = np.array(img, dtype=np.float32)[:, :, :3]
    with open(out, 'wb') as f:
        f.write(b'PF\n%d %d\n-1.0\n' % (a.shape[1], a.shape[0]))
        f.write(np.ascontiguousarray(a[::-1]).tobytes())
    print(json.dumps({'renderer': 'mitsuba3-' + mi.variant(), 'scene': scene, 'spp': spp, 'load_s': t1 - t0,
                      'render_s': t2 - t1}))


if __name__ == '__main__':
    if len(sys.argv) != 9 or sys.argv[1] != 'mitsuba':
        raise SystemExit(__doc__.split('usage')[1].split('\n', 1)[1].split('renders')[0].strip())
    mitsuba_main(sys.argv[2:])
