/*
 * test_kernels.c — every kernel run through OpenCL (the first OpenCL CPU device: PoCL
 * here) and through the scalar C path on the same inputs, outputs compared.
 *
 * Both sides compile the same source (kernels/), use the same random numbers and avoid
 * every operation whose rounding is implementation-defined, so the goal is identical
 * bits; the assertions use the stated tolerances (hits: same primitive and t within 1e-5
 * relative; colours within 1e-5 relative) and the test prints how many results were
 * bit-identical.
 */
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "layout.h"
#include "device/kernel_features.h"
#include "base/timer.h"
#include "device/ocl_program.h"
#include "render/render_scene.h"
#include "io/texture.h"

/* the kernel stage functions, compiled as C: the reference */
#include "film/film.h"
#include "integrator/raygen.h"
#include "integrator/shade_path.h"
#include "accel/traverse.h"
#include "integrator/whitted.h"
#include "medium/transmit.h"

/* Scene buffers every kernel takes first (SCENE_ARGS in entry.cl). */
#define N_SCENE SCENE_BUF_COUNT
#define N_SCENE_MAX 32
_Static_assert(N_SCENE <= N_SCENE_MAX, "N_SCENE_MAX");

typedef struct {
    OclDeviceInfo dev;
    cl_context ctx;
    cl_command_queue q;
    cl_program prog;
    cl_mem scene[N_SCENE];
    int ok;
} Cl;

static Cl cl;
static Scene scene;
static RenderScene rs;
static uint plain_material;   /* untextured diffuse: the surfaces k_path_lanes shades eight at a time */
/* A second scene, of the kind k_path_lanes renders (kernel_lanes_scene): flat diffuse
 * triangles and triangle lamps under a sky. */
static Scene lanes_scene;
static RenderScene lanes_rs;
static SceneView lanes_view;
static cl_mem lanes_bufs[N_SCENE_MAX];
static uint lanes_plain;
static KdTree kd;         /* the scene's kd-tree beside its BVH, for the kd-tree kernels */
static SceneView view;    /* the C side's view of the same scene */

static unsigned rng_state = 12345u;
static float frand(void)
{
    rng_state = rng_state * 1664525u + 1013904223u;
    return (float)(rng_state >> 8) * (1.0f / 16777216.0f);
}
static float frange(float lo, float hi) { return lo + (hi - lo) * frand(); }
static vec3 vrand(float lo, float hi) { return v3(frange(lo, hi), frange(lo, hi), frange(lo, hi)); }

/* Textures of each kind: an sRGB 8-bit image (nearest, mirrored in v), a linear float
 * image (mirrored in u, clamped in v), a surface checker, a solid one, and a float image
 * of values that render_scene_prepare packs as RGBE words (TEX_RGBE). Returns the
 * indices in t[5]. */
static void add_textures(uint t[5])
{
    uint px[8 * 4], offset;
    for (uint i = 0; i < 8 * 4; i++) px[i] = ((i * 37u) & 255u) | ((i * 91u) & 255u) << 8 | ((i * 13u) & 255u) << 16;
    scene_add_texels(&scene, px, 8 * 4, &offset, NULL);
    Texture img = texture_make_checker(v3s(0.0f), v3s(0.0f), 1.0f, 0);
    img.type = TEX_IMAGE;
    img.flags = TEX_SRGB | TEX_MIRROR_V | TEX_NEAREST;   /* u repeats */
    img.offset = offset;
    img.width = 8;
    img.height = 4;
    texture_set_scale_offset(&img, 3.0f, 2.0f, 0.1f, 0.0f);
    scene_add_texture(&scene, "image", NULL, img, &t[0], NULL);
    float f[6] = { 0.2f, 0.4f, 0.6f, 0.9f, 0.1f, 0.3f };
    uint bits[6];
    memcpy(bits, f, sizeof bits);
    scene_add_texels(&scene, bits, 6, &offset, NULL);
    img.flags = TEX_FLOAT | TEX_MIRROR_U | TEX_CLAMP_V;
    img.offset = offset;
    img.width = 2;
    img.height = 1;
    scene_add_texture(&scene, "float", NULL, img, &t[1], NULL);
    scene_add_texture(&scene, "uv", NULL, texture_make_checker(v3(0.9f, 0.9f, 0.9f), v3(0.1f, 0.2f, 0.3f), 4.0f, 0),
                      &t[2], NULL);
    scene_add_texture(&scene, "solid", NULL, texture_make_checker(v3(0.8f, 0.1f, 0.1f), v3(0.1f, 0.1f, 0.8f), 1.5f, 1),
                      &t[3], NULL);
    float hdr[12] = { 1.5f, 0.25f, 0.0f, 0.75f, 3.0f, 0.5f, 0.0f, 0.0f, 0.0f, 12.0f, 16.0f, 9.0f };
    uint hbits[12];
    memcpy(hbits, hdr, sizeof hbits);
    scene_add_texels(&scene, hbits, 12, &offset, NULL);
    img.flags = TEX_FLOAT;
    img.offset = offset;
    img.width = 2;
    img.height = 2;
    scene_add_texture(&scene, "rgbe", NULL, img, &t[4], NULL);
}

/* Six 3x2 linear, clamped image faces of varied texels for a cube-map background (the
 * scene keeps its sky; the tests switch params to the cube map). Returns the first. */
static uint cube_first;
static void add_cube_faces(void)
{
    for (uint f = 0; f < 6; f++) {
        uint px[6], offset, index;
        for (uint i = 0; i < 6; i++)
            px[i] = ((f * 41u + i * 67u) & 255u) | ((f * 13u + i * 29u + 80u) & 255u) << 8 |
                    ((f * 97u + i * 5u + 30u) & 255u) << 16;
        scene_add_texels(&scene, px, 6, &offset, NULL);
        Texture t = texture_make_checker(v3s(0.0f), v3s(0.0f), 1.0f, 0);
        t.type = TEX_IMAGE;
        t.flags = TEX_CLAMP;
        t.offset = offset;
        t.width = 3;
        t.height = 2;
        scene_add_texture(&scene, NULL, NULL, t, &index, NULL);
        if (f == 0) cube_first = index;
    }
}

/* A small scene with every primitive type and material type, and lights of each
 * lightable shape. */
static void build_scene(void)
{
    scene_init(&scene);
    scene.image.width = 32;
    scene.image.height = 24;
    scene.image.max_depth = 6;
    scene.image.seed = 99;
    scene.camera.from = v3(0.0f, 2.0f, 9.0f);
    scene.camera.at = v3(0.0f, 0.5f, 0.0f);
    scene.camera.aperture = 0.2f;
    scene.camera.focus_dist = 8.0f;
    scene.bg_type = BG_SKY;
    scene.bg_color = v3(1.0f, 1.0f, 1.0f);
    scene.bg_zenith = v3(0.5f, 0.7f, 1.0f);
    uint diffuse, metal, glass, lamp, glow;
    scene_add_material(&scene, "diffuse", material_diffuse(v3(0.7f, 0.5f, 0.3f)), &diffuse, NULL);
    scene_add_material(&scene, "metal", material_metal(v3(0.9f, 0.9f, 0.8f), 0.2f), &metal, NULL);
    scene_add_material(&scene, "glass", material_dielectric(1.5f), &glass, NULL);
    scene_add_material(&scene, "lamp", material_emissive(v3(6.0f, 5.0f, 4.0f)), &lamp, NULL);
    Material g = material_diffuse(v3s(0.4f));
    g.emission = v3(0.5f, 0.2f, 0.1f);
    /* the classic ray tracer's materials, textured in every way */
    uint tex[5], phong, mirror, clear, checked;
    add_textures(tex);
    g.texture_emission = tex[4];
    scene_add_material(&scene, "glow", g, &glow, NULL);
    add_cube_faces();
    Material ph = material_phong(v3(0.6f, 0.5f, 0.4f), v3(0.3f, 0.3f, 0.3f), 25.0f);
    ph.texture = tex[0];
    scene_add_material(&scene, "phong", ph, &phong, NULL);
    ph = material_phong(v3(0.1f, 0.1f, 0.1f), v3(0.5f, 0.5f, 0.5f), 200.0f);
    ph.reflective = v3(0.6f, 0.6f, 0.5f);
    ph.texture = tex[1];
    scene_add_material(&scene, "mirror", ph, &mirror, NULL);
    ph = material_phong(v3s(0.0f), v3(0.2f, 0.2f, 0.2f), 60.0f);
    ph.transparent = v3(0.9f, 0.9f, 0.8f);
    ph.reflective = v3s(0.05f);
    ph.ior = 1.4f;
    scene_add_material(&scene, "clear", ph, &clear, NULL);
    Material ch = material_diffuse(v3s(0.5f));
    ch.texture = tex[2];
    scene_add_material(&scene, "checked", ch, &checked, NULL);
    scene.materials[diffuse].texture = tex[3];
    /* the microfacet materials: rough and smooth conductors (one textured, one by
     * Schlick's F0), rough glass and a rough thin sheet */
    uint gold, chrome, frosted, sheet;
    Material cm = material_conductor(v3(0.17f, 0.35f, 1.5f), v3(3.1f, 2.7f, 1.9f), 0.4f);
    cm.anisotropy = 0.5f;
    cm.texture = tex[2];
    scene_add_material(&scene, "gold", cm, &gold, NULL);
    scene_add_material(&scene, "chrome", material_conductor_f0(v3(0.55f, 0.56f, 0.55f), 0.0f), &chrome, NULL);
    Material dm = material_dielectric(1.5f);
    dm.roughness = 0.3f;
    scene_add_material(&scene, "frosted", dm, &frosted, NULL);
    dm.flags |= MAT_THIN;
    dm.roughness = 0.5f;
    scene_add_material(&scene, "sheet", dm, &sheet, NULL);
    /* principled: textured plastic, and coated, transmitting and glowing mixtures */
    uint plastic, coated;
    Material pm = material_principled(v3(0.8f, 0.2f, 0.1f), 0.0f, 0.5f);
    pm.texture = tex[3];
    pm.texture_rm = tex[0];
    pm.metallic = 0.7f;
    scene_add_material(&scene, "plastic", pm, &plastic, NULL);
    pm = material_principled(v3(0.3f, 0.6f, 0.9f), 0.4f, 0.3f);
    pm.transmission = 0.6f;
    pm.clearcoat = 0.8f;
    pm.clearcoat_roughness = 0.1f;
    pm.emission = v3(0.2f, 0.1f, 0.0f);
    pm.texture_normal = tex[1];
    pm.normal_scale = 0.8f;
    scene_add_material(&scene, "coated", pm, &coated, NULL);
    /* pbrt's coated materials (kernels/bsdf/layered.h): textured plastic in a scattering
     * medium under a rough coat, and a coated rough conductor */
    uint lacquer, coated_metal;
    Material lm = material_coated_diffuse(v3(0.7f, 0.3f, 0.2f), 0.3f);
    lm.texture = tex[2];
    lm.layer_albedo = v3(0.8f, 0.8f, 0.6f);
    lm.layer_thickness = 0.2f;
    lm.layer_g = 0.3f;
    scene_add_material(&scene, "lacquer", lm, &lacquer, NULL);
    scene_add_material(&scene, "coated metal",
                       material_coated_conductor(v3(0.17f, 0.35f, 1.5f), v3(3.1f, 2.7f, 1.9f), 0.3f, 0.0f),
                       &coated_metal, NULL);
    uint mats[] = { diffuse, metal, glass, phong, glow, mirror, clear, checked, gold, chrome, frosted, sheet,
                    plastic, coated, lacquer, coated_metal };
    for (int i = 0; i < 16; i++) {
        Sphere s = { vrand(-3.0f, 3.0f), frange(0.2f, 0.8f), mats[i % 16], NO_INDEX, 0, 0 };
        scene_add_sphere(&scene, s, NULL);
    }
    Sphere light_sphere = { v3(0.0f, 5.0f, 0.0f), 0.5f, lamp, NO_INDEX, 0, 0 };
    scene_add_sphere(&scene, light_sphere, NULL);
    scene_add_material(&scene, "plain", material_diffuse(v3(0.6f, 0.6f, 0.5f)), &plain_material, NULL);
    for (int i = 0; i < 30; i++) {
        vec3 c = vrand(-3.0f, 3.0f);
        uint m = i % 3 == 0 ? plain_material : mats[i % 16];
        Triangle t = { v3_add(c, vrand(-1.0f, 1.0f)), m, v3_add(c, vrand(-1.0f, 1.0f)), NO_INDEX,
                       v3_add(c, vrand(-1.0f, 1.0f)), NO_INDEX };
        scene_add_triangle(&scene, t, NULL);
    }
    /* a bright lamp triangle and (below) quad, facing down, which the light choice picks
     * often, so that k_path_lanes samples both kinds in float8 */
    uint panel;
    scene_add_material(&scene, "panel", material_emissive(v3(60.0f, 50.0f, 40.0f)), &panel, NULL);
    Triangle lt = { v3(-1.0f, 4.0f, -1.0f), panel, v3(1.0f, 4.0f, -1.0f), NO_INDEX, v3(0.0f, 4.0f, 1.0f), NO_INDEX };
    scene_add_triangle(&scene, lt, NULL);
    /* a floor under it all */
    Triangle f1 = { v3(-10.0f, -1.2f, -10.0f), plain_material, v3(-10.0f, -1.2f, 10.0f), NO_INDEX,
                    v3(10.0f, -1.2f, 10.0f), NO_INDEX };
    Triangle f2 = { v3(-10.0f, -1.2f, -10.0f), plain_material, v3(10.0f, -1.2f, 10.0f), NO_INDEX,
                    v3(10.0f, -1.2f, -10.0f), NO_INDEX };
    scene_add_triangle(&scene, f1, NULL);
    scene_add_triangle(&scene, f2, NULL);
    /* the quad lamp: two triangles, sampled as one parallelogram */
    Triangle q1 = { v3(-1.0f, 4.5f, 2.0f), panel, v3(1.0f, 4.5f, 2.0f), NO_INDEX, v3(1.0f, 4.5f, 3.0f), NO_INDEX };
    Triangle q2 = { v3(-1.0f, 4.5f, 2.0f), panel, v3(1.0f, 4.5f, 3.0f), NO_INDEX, v3(-1.0f, 4.5f, 3.0f), NO_INDEX };
    scene_add_triangle(&scene, q1, NULL);
    scene_add_triangle(&scene, q2, NULL);
    for (int i = 0; i < 4; i++) {
        vec3 lo = vrand(-3.0f, 2.0f);
        Box b = { lo, mats[(i * 3) % 14], v3_add(lo, vrand(0.2f, 1.0f)), NO_INDEX };
        scene_add_box(&scene, b, NULL);
    }
    Box lb = { v3(2.0f, 3.0f, 2.0f), lamp, v3(2.5f, 3.2f, 2.4f), NO_INDEX };
    scene_add_box(&scene, lb, NULL);
    /* surfaces of revolution: two cubic pieces and a degree-5 Bezier profile */
    const float vase[2 * 7] = { 0, 0, 0.4f, 0, 0.7f, 0.3f, 0.6f, 0.8f, 0.5f, 1.3f, 0.3f, 1.6f, 0.45f, 2.0f };
    const float bowl[2 * 6] = { 0, 0, 0.6f, 0, 0.8f, 0.2f, 0.9f, 0.5f, 1.0f, 0.6f, 1.1f, 0.7f };
    RevSurface rv = { v3s(0.0f), phong, v3s(0.0f), 0u, -1.5f, 1.0f, 2u, 3u };
    scene_add_revsurface(&scene, rv, vase, NULL);
    RevSurface rb = { v3s(0.0f), mirror, v3s(0.0f), 0u, 1.5f, -0.5f, 1u, 5u };
    scene_add_revsurface(&scene, rb, bowl, NULL);
    Plane floor = { v3(0.0f, 1.0f, 0.0f), -3.5f, checked, 0, 0, 0 };
    scene_add_plane(&scene, floor, NULL);
    /* delta lights of every kind, with the classic and the physical attenuation */
    Light pt = light_default(LIGHT_POINT);
    pt.position = v3(-2.0f, 4.0f, 3.0f);
    pt.intensity = v3(8.0f, 8.0f, 7.0f);
    scene_add_light(&scene, pt, NULL);
    Light spot = light_default(LIGHT_SPOT);
    spot.position = v3(2.0f, 5.0f, 2.0f);
    spot.direction = v3_norm(v3(-0.3f, -1.0f, -0.2f));
    spot.intensity = v3(20.0f, 18.0f, 15.0f);
    spot.cos_outer = 0.8f;
    spot.cos_inner = 0.9f;
    spot.atten0 = 1.0f;
    spot.atten1 = 0.1f;
    spot.atten2 = 0.0f;
    scene_add_light(&scene, spot, NULL);
    spot.position = v3(-2.0f, 5.0f, -1.0f);
    spot.spot_falloff = SPOT_GLTF;
    scene_add_light(&scene, spot, NULL);
    Light dir = light_default(LIGHT_DIRECTIONAL);
    dir.direction = v3_norm(v3(0.4f, -1.0f, -0.3f));
    dir.intensity = v3(1.0f, 1.0f, 1.2f);
    scene_add_light(&scene, dir, NULL);
    scene.ambient = v3(0.05f, 0.05f, 0.05f);
    Error err = { 0 };
    Status st = render_scene_prepare(&scene, 1, &rs, &err);
    if (!st && !(scene.textures[tex[4]].flags & TEX_RGBE)) {
        fprintf(stderr, "the float texture of RGBE values was not packed\n");
        abort();
    }
    /* the renderer walks the BVH (rs); the kd-tree's own kernels get the kd-tree too */
    KdInput in = { scene.spheres, scene.n_spheres, scene.triangles, scene.n_triangles, scene.boxes, scene.n_boxes,
                   scene.revsurfaces, scene.n_revsurfaces, scene.sphere_xforms, scene.n_sphere_xforms, NULL, 0 };
    if (!st) st = kd_build(&in, 1, &kd, &err);
    if (st) fprintf(stderr, "scene setup failed: %s\n", err.msg);
    render_scene_use_kdtree(&rs.ds, &kd);
    device_scene_view(&rs.ds, &view);
}

/* The lanes scene: plain diffuse triangles of two albedos over a floor, a lamp triangle,
 * a quad lamp and a two-sided lamp, a sky to escape to, and few enough bounces that
 * paths reach the last one. */
static void build_lanes_scene(void)
{
    Scene *sc = &lanes_scene;
    scene_init(sc);
    sc->image.width = 32;
    sc->image.height = 24;
    sc->image.max_depth = 4;
    sc->image.seed = 7;
    sc->camera.from = v3(0.0f, 2.0f, 9.0f);
    sc->camera.at = v3(0.0f, 0.5f, 0.0f);
    sc->camera.aperture = 0.2f;
    sc->camera.focus_dist = 8.0f;
    sc->bg_type = BG_SKY;
    sc->bg_color = v3(0.3f, 0.3f, 0.3f);
    sc->bg_zenith = v3(0.2f, 0.3f, 0.5f);
    uint other, panel, both;
    scene_add_material(sc, "plain", material_diffuse(v3(0.6f, 0.6f, 0.5f)), &lanes_plain, NULL);
    scene_add_material(sc, "other", material_diffuse(v3(0.3f, 0.5f, 0.7f)), &other, NULL);
    scene_add_material(sc, "panel", material_emissive(v3(60.0f, 50.0f, 40.0f)), &panel, NULL);
    Material two = material_emissive(v3(5.0f, 6.0f, 8.0f));
    two.flags |= MAT_TWO_SIDED;
    scene_add_material(sc, "both", two, &both, NULL);
    for (int i = 0; i < 40; i++) {
        vec3 c = vrand(-3.0f, 3.0f);
        uint m = i % 2 ? lanes_plain : other;
        Triangle t = { v3_add(c, vrand(-1.0f, 1.0f)), m, v3_add(c, vrand(-1.0f, 1.0f)), NO_INDEX,
                       v3_add(c, vrand(-1.0f, 1.0f)), NO_INDEX };
        scene_add_triangle(sc, t, NULL);
    }
    Triangle f1 = { v3(-10.0f, -1.2f, -10.0f), lanes_plain, v3(-10.0f, -1.2f, 10.0f), NO_INDEX,
                    v3(10.0f, -1.2f, 10.0f), NO_INDEX };
    Triangle f2 = { v3(-10.0f, -1.2f, -10.0f), lanes_plain, v3(10.0f, -1.2f, 10.0f), NO_INDEX,
                    v3(10.0f, -1.2f, -10.0f), NO_INDEX };
    Triangle lt = { v3(-1.0f, 4.0f, -1.0f), panel, v3(1.0f, 4.0f, -1.0f), NO_INDEX, v3(0.0f, 4.0f, 1.0f), NO_INDEX };
    Triangle q1 = { v3(-1.0f, 4.5f, 2.0f), panel, v3(1.0f, 4.5f, 2.0f), NO_INDEX, v3(1.0f, 4.5f, 3.0f), NO_INDEX };
    Triangle q2 = { v3(-1.0f, 4.5f, 2.0f), panel, v3(1.0f, 4.5f, 3.0f), NO_INDEX, v3(-1.0f, 4.5f, 3.0f), NO_INDEX };
    Triangle wall = { v3(3.5f, -1.0f, -2.0f), both, v3(3.5f, 2.0f, -2.0f), NO_INDEX, v3(3.5f, 0.5f, 1.0f), NO_INDEX };
    const Triangle *more[] = { &f1, &f2, &lt, &q1, &q2, &wall };
    for (size_t i = 0; i < sizeof more / sizeof more[0]; i++) scene_add_triangle(sc, *more[i], NULL);
    Error err = { 0 };
    if (render_scene_prepare(sc, 1, &lanes_rs, &err)) fprintf(stderr, "lanes scene setup failed: %s\n", err.msg);
    device_scene_view(&lanes_rs.ds, &lanes_view);
}

/* a buffer made as the renderer makes a scene's (ocl_buffer: on huge pages on a CPU,
 * handed to the driver), so that the kernels' bits are compared on that memory too */
static cl_mem buffer(size_t bytes, const void *src)
{
    cl_int rc;
    const char *call;
    cl_mem m = ocl_buffer(cl.ctx, cl.dev.type, CL_MEM_READ_WRITE, OCL_READ_AT_RANDOM, bytes, src, &call, &rc);
    CHECK_MSG(m != NULL, "%s: %s", call, ocl_error_name(rc));
    return m;
}

static void read_back(cl_mem m, size_t bytes, void *dst)
{
    cl_int rc = clEnqueueReadBuffer(cl.q, m, CL_TRUE, 0, bytes, dst, 0, NULL, NULL);
    CHECK_MSG(rc == CL_SUCCESS, "clEnqueueReadBuffer: %s", ocl_error_name(rc));
}

static cl_kernel kernel(const char *name)
{
    cl_kernel k = NULL;
    Error err = { 0 };
    Status st = ocl_program_kernel(cl.prog, &cl.dev, name, &k, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    return k;
}

#define SET(k, i, v) CHECK(clSetKernelArg(k, i, sizeof(v), &(v)) == CL_SUCCESS)

/* Launches n work-items (at least) as the renderer does (device_ocl.c): in work-groups
 * of 64 where the device allows, the global size rounded up, which every kernel's own
 * count check absorbs. Left to choose, PoCL picked work-groups of thousands here and
 * kept every work-item's private arrays (the traversal stacks) on one worker thread's
 * stack: k_shadow overflowed its 8 MB in about one cold run in three (a 9.5 MB frame,
 * gdb). */
static void run(cl_kernel k, size_t n)
{
    size_t local = cl.dev.max_work_group >= 64 ? 64 : 0, global = local ? (n + local - 1) / local * local : n;
    cl_int rc = clEnqueueNDRangeKernel(cl.q, k, 1, NULL, &global, local ? &local : NULL, 0, NULL, NULL);
    CHECK_MSG(rc == CL_SUCCESS, "clEnqueueNDRangeKernel: %s", ocl_error_name(rc));
    CHECK(clFinish(cl.q) == CL_SUCCESS);
}

static void set_scene_bufs(cl_kernel k, const cl_mem *bufs)
{
    for (cl_uint i = 0; i < N_SCENE; i++) SET(k, i, bufs[i]);
}

static void set_scene_args(cl_kernel k) { set_scene_bufs(k, cl.scene); }

static int setup_opencl(void)
{
    OclDeviceInfo *devs = NULL;
    size_t n = 0;
    Error err = { 0 };
    if (ocl_enumerate(&devs, &n, &err) != ST_OK || n == 0) {
        fprintf(stderr, "no OpenCL device: %s\n", err.msg);
        free(devs);
        return 0;
    }
    cl_device_type want = TEST_OPENCL_IS_GPU ? CL_DEVICE_TYPE_GPU : CL_DEVICE_TYPE_CPU;
    size_t pick = TEST_OPENCL_IS_GPU ? n : 0;   /* a GPU asked for and none: no device */
    for (size_t i = 0; i < n; i++)
        if (devs[i].type & want) { pick = i; break; }
    if (pick == n) {
        fprintf(stderr, "CLPT_TEST_OPENCL=gpu: no OpenCL GPU\n");
        free(devs);
        return 0;
    }
    cl.dev = devs[pick];
    fprintf(stderr, "  kernels compared on %s (%s)\n", cl.dev.name, cl.dev.platform_version);
    free(devs);
    cl_int rc;
    cl.ctx = clCreateContext(NULL, 1, &cl.dev.id, NULL, NULL, &rc);
    if (rc != CL_SUCCESS) return 0;
    cl.q = clCreateCommandQueue(cl.ctx, cl.dev.id, 0, &rc);
    if (rc != CL_SUCCESS) return 0;
    OclProgramStats ps;
    if (ocl_program_build(cl.ctx, &cl.dev, NULL, NULL, &cl.prog, &ps, &err) != ST_OK) {
        fprintf(stderr, "%s\n%s\n", err.msg, err.detail ? err.detail : "");
        error_clear(&err);
        return 0;
    }
    for (unsigned i = 0; i < N_SCENE; i++) {
        SceneBufferBytes b = device_scene_buffer(&rs.ds, i);
        cl.scene[i] = buffer(b.bytes, b.data);
        b = device_scene_buffer(&lanes_rs.ds, i);
        lanes_bufs[i] = buffer(b.bytes, b.data);
    }
    return 1;
}

static int rel_close(float a, float b, float tol)
{
    if (a == b) return 1;
    float m = k_fmax(k_fabs(a), k_fabs(b));
    return k_fabs(a - b) <= tol * (m > 1.0f ? m : 1.0f);
}
static int v3_close(vec3 a, vec3 b, float tol)
{
    return rel_close(a.x, b.x, tol) && rel_close(a.y, b.y, tol) && rel_close(a.z, b.z, tol);
}

/* Prints the 4-byte words in which the C result and the device's differ (as floats and
 * as bits), so that a device's difference points at a field rather than a count. */
static void report_words(const char *what, uint index, const void *c, const void *dev, size_t bytes)
{
    const unsigned char *a = c, *b = dev;
    for (size_t j = 0; j + 4 <= bytes; j += 4) {
        if (!memcmp(a + j, b + j, 4)) continue;
        float fa, fb;
        uint ua, ub;
        memcpy(&fa, a + j, 4);
        memcpy(&fb, b + j, 4);
        memcpy(&ua, a + j, 4);
        memcpy(&ub, b + j, 4);
        fprintf(stderr, "    %s %u, word %zu: C %a (0x%08x), device %a (0x%08x)\n", what, index, j / 4,
                (double)fa, ua, (double)fb, ub);
    }
}

static void test_layout(void)
{
    uint host[] = LAYOUT_HOST_VALUES;
    enum { N = sizeof host / sizeof host[0] };
    uint dev[N];
    cl_mem out = buffer(sizeof dev, NULL);
    cl_kernel k = kernel("k_layout");
    SET(k, 0, out);
    run(k, 1);
    read_back(out, sizeof dev, dev);
    for (int i = 0; i < N; i++) CHECK_MSG(dev[i] == host[i], "layout entry %d: device %u, host %u", i, dev[i], host[i]);
    clReleaseKernel(k);
    clReleaseMemObject(out);
}

enum { LAYERS = 3 };

static void test_raygen(void)
{
    const RenderParams *p = &rs.ds.params;
    uint npix = p->width * p->height, n = npix * LAYERS, first_pixel = 0, first_sample = 5;
    cl_mem paths = buffer(n * sizeof(PathState), NULL), rays = buffer(n * sizeof(Ray), NULL),
           queue = buffer(n * sizeof(uint), NULL);
    cl_kernel k = kernel("k_raygen");
    set_scene_args(k);
    SET(k, N_SCENE + 0, first_pixel);
    SET(k, N_SCENE + 1, first_sample);
    SET(k, N_SCENE + 2, npix);
    SET(k, N_SCENE + 3, n);
    SET(k, N_SCENE + 4, paths);
    SET(k, N_SCENE + 5, rays);
    SET(k, N_SCENE + 6, queue);
    run(k, n);
    PathState *dp = malloc(n * sizeof *dp);
    Ray *dr = malloc(n * sizeof *dr);
    uint *dq = malloc(n * sizeof *dq);
    read_back(paths, n * sizeof *dp, dp);
    read_back(rays, n * sizeof *dr, dr);
    read_back(queue, n * sizeof *dq, dq);
    uint exact = 0, bad = 0;
    for (uint i = 0; i < n; i++) {
        PathState cp;
        Ray cr;
        raygen_path(p, NULL, i % npix, first_sample + i / npix, &cp, &cr);
        exact += memcmp(&cp, &dp[i], sizeof cp) == 0 && memcmp(&cr, &dr[i], sizeof cr) == 0;
        if (dp[i].pixel != cp.pixel || dp[i].sample != cp.sample || dp[i].rng_key != cp.rng_key ||
            !v3_close(dr[i].o, cr.o, 1e-6f) || !v3_close(dr[i].d, cr.d, 1e-6f) || dq[i] != i)
            bad++;
    }
    fprintf(stderr, "  k_raygen: %u of %u paths bit-identical to C\n", exact, n);
    CHECK_MSG(bad == 0, "%u of %u camera rays differ", bad, n);
    free(dp);
    free(dr);
    free(dq);
    clReleaseKernel(k);
    clReleaseMemObject(paths);
    clReleaseMemObject(rays);
    clReleaseMemObject(queue);
}

/* k_path, the megakernel (the CPUs' form of the path tracer): every path from birth to
 * end in one work-item, against the scalar device's loop in C (device_scalar.c): the
 * same path states bit for bit, and the same number of rays, counted per work-group
 * into a low word and a carry word. Launched with surplus work-items. k_path_lanes
 * (per_item PATH_LANES paths per work-item) must give the same; the last work-item has
 * fewer than eight paths. */
static void check_path_kernel(const char *name, uint per_item, const RenderScene *scn, const SceneView *scene_view,
                              const cl_mem *bufs, uint plain, int listed)
{
    /* listed: a batch over a pixel list (RenderParams.pixel_list_size): every third
     * pixel and the last, whose paths must be those an unlisted batch gives them */
    RenderParams lp = scn->ds.params;
    uint *list = malloc((size_t)lp.width * lp.height * sizeof *list);
    if (listed) {
        for (uint i = 0; i < lp.width * lp.height; i++)
            if (i % 3u == 1u || i + 1u == lp.width * lp.height) list[lp.pixel_list_size++] = i;
    }
    SceneView lv = *scene_view;
    lv.params = &lp;
    lv.pixel_list = list;
    const SceneView *v = &lv;
    const RenderParams *p = &lp;
    /* a last work-item of k_path_lanes with fewer than eight paths */
    uint npix = listed ? lp.pixel_list_size : p->width * p->height;
    uint n = npix * LAYERS - (per_item > 1u ? 5u : 0u), first_pixel = 7, first_sample = 3;
    cl_uint init[2 * QUEUE_COUNT_STRIDE] = { 0 };
    init[0] = 0xfffff000u;   /* near the top: the count wraps the low word and carries */
    cl_mem paths = buffer(n * sizeof(PathState), NULL), rays = buffer(n * sizeof(Ray), NULL),
           shadow = buffer(n * sizeof(Ray), NULL), counters = buffer(sizeof init, init);
    cl_mem list_params = listed ? buffer(sizeof lp, &lp) : NULL;
    cl_mem list_pixels = listed ? buffer(lp.pixel_list_size * sizeof *list, list) : NULL;
    cl_kernel k = kernel(name);
    set_scene_bufs(k, bufs);
    if (listed) {
        SET(k, SCENE_BUF_params, list_params);
        SET(k, SCENE_BUF_pixel_list, list_pixels);
    }
    SET(k, N_SCENE + 0, first_pixel);
    SET(k, N_SCENE + 1, first_sample);
    SET(k, N_SCENE + 2, npix);
    SET(k, N_SCENE + 3, n);
    SET(k, N_SCENE + 4, paths);
    SET(k, N_SCENE + 5, rays);
    SET(k, N_SCENE + 6, shadow);
    SET(k, N_SCENE + 7, counters);
    run(k, (n + per_item - 1u) / per_item + 37u);
    PathState *dp = malloc(n * sizeof *dp);
    cl_uint got[2 * QUEUE_COUNT_STRIDE];
    read_back(paths, n * sizeof *dp, dp);
    read_back(counters, sizeof got, got);
    uint exact = 0, lit = 0, plain_hits = 0;
    uint64_t c_rays = 0;
    for (uint i = 0; i < n; i++) {
        PathState cp;
        Ray cr, cs;
        memset(&cs, 0, sizeof cs);
        uint path = first_pixel + i;
        raygen_path(p, v->motion_keys, batch_pixel(v, path % npix), first_sample + path / npix, &cp, &cr);
        for (;;) {
            Hit hit = trace_closest_visible(v, cr);
            c_rays++;
            uint first_tri = p->n_spheres;
            if (hit.prim != NO_INDEX && hit.prim >= first_tri && hit.prim < first_tri + p->n_triangles &&
                v->triangles[hit.prim - first_tri].material == plain)
                plain_hits++;
            uint r = shade_path(v, &cr, hit, &cp, &cs);
            if (r & SHADE_SHADOW) {
                shadow_resolve(&cp, trace_occluded(v, cs));
                c_rays++;
            }
            if (!(r & SHADE_CONTINUE)) break;
        }
        int same = memcmp(&cp, &dp[i], sizeof cp) == 0;
        exact += same;
        lit += cp.radiance.x > 0.0f;
        if (!same && i + 1 - exact <= 3) report_words("path state", i, &cp, &dp[i], sizeof cp);
    }
    uint64_t d_rays = (uint64_t)got[0] + ((uint64_t)got[QUEUE_COUNT_STRIDE] << 32);
    fprintf(stderr, "  %s%s: %u paths, %u lit, %llu rays (%u hits on plain diffuse triangles), %u bit-identical to C\n",
            name, listed ? " over a pixel list" : "", n, lit, (unsigned long long)c_rays, plain_hits, exact);
    CHECK_EQ_INT(exact, n);
    CHECK(plain_hits > n / 4);
    CHECK(lit > n / 4);
    CHECK_MSG(d_rays == 0xfffff000ull + c_rays, "rays: device %llu, C %llu", (unsigned long long)(d_rays - 0xfffff000ull),
              (unsigned long long)c_rays);
    /* the whole batches carry; a listed one may trace too few rays to */
    CHECK_EQ_INT(got[QUEUE_COUNT_STRIDE], (uint)((0xfffff000ull + c_rays) >> 32));
    if (!listed) CHECK_EQ_INT(got[QUEUE_COUNT_STRIDE], 1);
    if (listed) {
        /* the pixels left out appear in no path */
        uint outside = 0;
        for (uint i = 0; i < n; i++) outside += dp[i].pixel % 3u != 1u && dp[i].pixel + 1u != p->width * p->height;
        CHECK_EQ_INT(outside, 0);
        clReleaseMemObject(list_params);
        clReleaseMemObject(list_pixels);
    }
    free(dp);
    free(list);
    clReleaseKernel(k);
    clReleaseMemObject(paths);
    clReleaseMemObject(rays);
    clReleaseMemObject(shadow);
    clReleaseMemObject(counters);
}

static void test_path_kernel(void) { check_path_kernel("k_path", 1u, &rs, &view, cl.scene, plain_material, 0); }

/* k_path over a pixel list (the noise threshold's rounds): each listed pixel's paths
 * are the bits it gets without a list. */
static void test_path_kernel_listed(void)
{
    check_path_kernel("k_path", 1u, &rs, &view, cl.scene, plain_material, 1);
}

/* k_path_lanes on the scene of its kind (it holds no shade_path, so it renders only
 * those), and which scenes are of that kind. */
static void test_path_lanes_kernel(void)
{
    const DeviceScene *ds = &lanes_rs.ds;
    CHECK(kernel_lanes_scene(ds, kernel_scene_features(ds)) && kernel_lanes_params(&ds->params));
    CHECK(!kernel_lanes_scene(&rs.ds, kernel_scene_features(&rs.ds)));
    /* a diffuse material that emits would need the full shading in k_path_lanes */
    DeviceScene glow = *ds;
    Material mats[8];
    CHECK(ds->n_materials <= 8);
    memcpy(mats, ds->materials, ds->n_materials * sizeof *mats);
    mats[lanes_plain].emission = v3(0.1f, 0.0f, 0.0f);
    glow.materials = mats;
    CHECK(!kernel_lanes_scene(&glow, kernel_scene_features(&glow)));
    /* other settings than the float8 shading's */
    RenderParams q = ds->params;
    q.sampler = SAMPLER_INDEPENDENT;
    CHECK(!kernel_lanes_params(&q));
    q = ds->params;
    q.shadows = 0;
    CHECK(!kernel_lanes_params(&q));
    q = ds->params;
    q.mis_mode = MIS_LIGHT_ONLY;
    CHECK(!kernel_lanes_params(&q));
    check_path_kernel("k_path_lanes", PATH_LANES, &lanes_rs, &lanes_view, lanes_bufs, lanes_plain, 0);
    check_path_kernel("k_path_lanes", PATH_LANES, &lanes_rs, &lanes_view, lanes_bufs, lanes_plain, 1);
}

/* Random rays through the scene's box, from inside and outside it. */
static Ray random_ray(void)
{
    Ray r;
    r.o = vrand(-6.0f, 6.0f);
    r.d = v3_norm(v3_sub(vrand(-3.0f, 3.0f), r.o));
    if (frand() < 0.1f) r.d.x = 0.0f;          /* zero direction components too */
    r.tmin = 0.0f;
    r.tmax = frand() < 0.2f ? frange(0.5f, 5.0f) : INFINITY;
    return r;
}

static void test_intersect(void)
{
    enum { N = 20000 };
    Ray *rays = malloc(N * sizeof *rays);
    uint *queue = malloc(N * sizeof *queue);
    for (uint i = 0; i < N; i++) {
        rays[i] = random_ray();
        queue[i] = N - 1 - i;                   /* a permuted queue, as after compaction */
    }
    cl_mem rb = buffer(N * sizeof *rays, rays), qb = buffer(N * sizeof *queue, queue), hb = buffer(N * sizeof(Hit), NULL);
    /* launched over an upper bound, as on a GPU: the live count on the device (count
     * slot 0 here) stops the work-items past it, and the surplus beyond n does nothing */
    cl_uint live_counts[QUEUE_COUNT_STRIDE] = { N }, live_slot = 0;
    cl_mem lcb = buffer(sizeof live_counts, live_counts);
    cl_kernel k = kernel("k_intersect");
    set_scene_args(k);
    uint n = N + 64;
    SET(k, N_SCENE + 0, qb);
    SET(k, N_SCENE + 1, n);
    SET(k, N_SCENE + 2, rb);
    SET(k, N_SCENE + 3, hb);
    SET(k, N_SCENE + 4, lcb);
    SET(k, N_SCENE + 5, live_slot);
    /* the paths' states: their time where the scene moves, and the medium each ray is
     * in (trace_flight): vacuum here, so that the walk looks as far as the ray goes */
    PathState *states = calloc(N, sizeof *states);
    cl_mem pb = buffer(N * sizeof(PathState), states);
    free(states);
    SET(k, N_SCENE + 6, pb);
    run(k, N + 100);
    Hit *dh = malloc(N * sizeof *dh);
    read_back(hb, N * sizeof *dh, dh);
    uint exact = 0, bad = 0, hits = 0;
    for (uint i = 0; i < N; i++) {
        Hit ch = trace_closest(&view, rays[i]);
        hits += ch.prim != NO_INDEX;
        exact += memcmp(&ch, &dh[i], sizeof ch) == 0;
        if (ch.prim != dh[i].prim || (ch.prim != NO_INDEX && !rel_close(ch.t, dh[i].t, 1e-5f))) bad++;
    }
    fprintf(stderr, "  k_intersect: %u rays, %u hits, %u bit-identical to C\n", (uint)N, hits, exact);
    CHECK(hits > N / 4);
    CHECK_MSG(bad == 0, "%u of %u hits differ", bad, (uint)N);
    CHECK_EQ_INT(exact, N);
    free(rays);
    free(queue);
    free(dh);
    clReleaseKernel(k);
    clReleaseMemObject(lcb);
    clReleaseMemObject(pb);
    clReleaseMemObject(rb);
    clReleaseMemObject(qb);
    clReleaseMemObject(hb);
}

/* trace_flight (kernels/medium/medium_path.h) for random rays through scene view `base`
 * in a homogeneous medium that scatters, each with a path state of its own; returns the
 * stops drawn before the walk. Where one is drawn it is the one medium_flight would
 * draw, where the whole walk's hit lies before it the shorter walk's is that hit bit for
 * bit, and everywhere else the flight stops there too; where none is drawn, the hit is
 * the whole walk's. *cut counts the walks that missed where the whole one hit. */
static uint check_flight_walk(const SceneView *base, uint n, uint *cut)
{
    Medium md;
    memset(&md, 0, sizeof md);
    md.type = MEDIUM_HOMOGENEOUS;
    md.sigma_a = v3(0.05f, 0.1f, 0.2f);
    md.sigma_s = v3(0.6f, 0.4f, 0.25f);   /* chromatic: the stop's channel varies */
    md.g = 0.3f;
    RenderParams p = *base->params;
    p.has_media = HAS_MEDIA_ANY;
    p.n_media = 1u;
    SceneView v = *base;
    v.params = &p;
    v.media = &md;
    uint drawn = 0, same = 0, passed = 0;
    *cut = 0;
    for (uint i = 0; i < n; i++) {
        Ray r = random_ray();
        PathState ps;
        memset(&ps, 0, sizeof ps);
        ps.medium = 1u;
        ps.throughput = v3(frange(0.0f, 1.0f), frange(0.0f, 1.0f), frange(0.0f, 1.0f));
        ps.pixel = i;
        ps.sample = i % 7u;
        ps.rng_key = 0x9e3779b9u * (i + 1u);
        ps.bounce = i % 4u;
        ps.crossings = i % 3u;
        Hit whole = trace_closest_visible(&v, r);
        Hit h = trace_flight(&v, r, &ps);
        if (!h.flight_drawn) {
            same += memcmp(&whole, &h, sizeof h) == 0;
            passed++;
            continue;
        }
        drawn++;
        float ts = medium_flight_stop(medium_sigma_t(md), medium_channel_pdf(ps.throughput), rng_key_of(&ps, &p),
                                      path_rng_bounce(&ps));
        CHECK(h.flight_stop == ts);
        float len = v3_len(r.d);
        float dist = whole.prim == NO_INDEX ? INFINITY : (whole.t - r.tmin) * len;
        float dist_h = h.prim == NO_INDEX ? INFINITY : (h.t - r.tmin) * len;
        if (!(ts < dist)) {   /* the flight passes to the whole walk's hit: the same hit */
            passed++;
            Hit w = whole;
            w.flight_stop = h.flight_stop;
            w.flight_drawn = h.flight_drawn;
            same += memcmp(&w, &h, sizeof h) == 0;
        } else {              /* it stops short of it: so it must with the shorter walk's */
            CHECK_MSG(ts < dist_h, "ray %u: the flight stops at %g, the whole walk's hit at %g, the shorter "
                      "walk's at %g", i, ts, dist, dist_h);
            *cut += whole.prim != NO_INDEX && h.prim == NO_INDEX;
        }
    }
    CHECK_MSG(same == passed, "%u of %u hits differ from the whole walk's", passed - same, passed);
    return drawn;
}

/* The walk that stops looking at a medium's stop: on the lanes scene (triangles, no
 * point light) a stop is drawn for every ray and most walks are cut short of a hit;
 * on the kernels' scene, which has surfaces of revolution, none is drawn. */
static void test_flight_walk(void)
{
    enum { N = 20000 };
    uint cut, drawn = check_flight_walk(&lanes_view, N, &cut);
    fprintf(stderr, "  trace_flight, triangles: %u rays, %u stops drawn, %u walks cut short of a hit\n",
            (uint)N, drawn, cut);
    CHECK_EQ_INT(drawn, N);
    CHECK(cut > N / 10);
    CHECK(view.params->n_revsurfaces > 0u);
    drawn = check_flight_walk(&view, N, &cut);
    fprintf(stderr, "  trace_flight, with surfaces of revolution: %u rays, %u stops drawn\n", (uint)N, drawn);
    CHECK_EQ_INT(drawn, 0);
}

/* A scene of media boundaries for test_shadow_through: a sphere of medium a holding a
 * box of b (its exterior a), a closed octahedron of triangles holding the grid medium g
 * and overlapping both, a second sphere of b inside the octahedron, and opaque shapes
 * among them (a sphere, a box, two triangles, a floor plane). */
static void shadow_through_scene_text(char *text, size_t size)
{
    int n = snprintf(text, size,
                     "image { width 8 height 8 spp 1 }\n"
                     "camera { from 0 0 12 at 0 0 0 up 0 1 0 fov 40 }\n"
                     "medium a { type homogeneous sigma_a 0.1 0.2 0.3 sigma_s 0.4 0.3 0.2 }\n"
                     "medium b { type homogeneous sigma_a 0.3 0.2 0.1 sigma_s 0.2 0.2 0.2 }\n"
                     "medium g { type grid sigma_a 0.2 0.2 0.2 sigma_s 0.5 0.6 0.7 size 2 2 2 "
                     "min 0 0 -1.5 max 3 3 1.5 data [ 0.1 0.9 0.5 0.2 1 0.3 0.7 0.4 ] }\n"
                     "material white { type diffuse albedo 0.5 0.5 0.5 }\n"
                     "sphere { center 0 0 0 radius 3 material none interior a }\n"
                     "box { min -1 -1 -1 max 1 1 1 material none interior b exterior a }\n"
                     "sphere { center 1.5 1.5 0 radius 0.4 material none interior b }\n"
                     "sphere { center -1.5 -2 0.5 radius 0.5 material white }\n"
                     "box { min 2 -2 -2 max 2.5 -1 2 material white }\n"
                     "triangle { v0 -4 3 -1 v1 -2 3 -1 v2 -3 3.5 1 material white }\n"
                     "triangle { v0 -1 -1.5 2 v1 1 -1.5 2 v2 0 -0.5 2.5 material white }\n"
                     "plane { point 0 -5 0 normal 0 1 0 material white }\n");
    /* a boundary and an opaque shape in the same place, in both orders of id: a ray
     * through them meets the two at the same t, where the walk from hit to hit takes the
     * lower id first (the boundary: it passes; the surface: it is blocked). Triangles of
     * one leaf group are told apart there as the walk from hit to hit tells them; two
     * spheres, tested one by one, leave the ray to that walk. */
    n += snprintf(text + n, size - (size_t)n,
                  "triangle { v0 -3.8 -4 -4 v1 -3.8 4 -4 v2 -3.8 0 4 material none interior b }\n"
                  "triangle { v0 -3.8 -4 -4 v1 -3.8 4 -4 v2 -3.8 0 4 material white }\n"
                  "triangle { v0 -4 -3.8 -4 v1 4 -3.8 -4 v2 0 -3.8 4 material white }\n"
                  "triangle { v0 -4 -3.8 -4 v1 4 -3.8 -4 v2 0 -3.8 4 material none interior b }\n"
                  "sphere { center -3.5 3.5 -3 radius 0.9 material white }\n"
                  "sphere { center -3.5 3.5 -3 radius 0.9 material none interior b }\n"
                  "sphere { center 3.5 -3.5 3 radius 0.9 material none interior a }\n"
                  "sphere { center 3.5 -3.5 3 radius 0.9 material white }\n");
    /* five slabs of b above it all: a ray up through them crosses ten boundaries, more
     * than the one walk keeps (THROUGH_MAX), and is walked from hit to hit */
    for (int k = 0; k < 5; k++)
        n += snprintf(text + n, size - (size_t)n, "box { min -4 %g -4 max 4 %g 4 material none interior b }\n",
                      3.5 + 0.2 * k, 3.6 + 0.2 * k);
    /* the octahedron around (1.5, 1.5, 0), radius 1.5, its faces outward */
    const float c[3] = { 1.5f, 1.5f, 0.0f }, r = 1.5f;
    for (int f = 0; f < 8; f++) {
        float sx = (f & 1) ? -r : r, sy = (f & 2) ? -r : r, sz = (f & 4) ? -r : r;
        float v[3][3] = { { c[0] + sx, c[1], c[2] }, { c[0], c[1] + sy, c[2] }, { c[0], c[1], c[2] + sz } };
        int odd = (sx < 0) ^ (sy < 0) ^ (sz < 0);   /* the winding that faces out */
        int i1 = odd ? 2 : 1, i2 = odd ? 1 : 2;
        n += snprintf(text + n, size - (size_t)n,
                      "triangle { v0 %g %g %g v1 %g %g %g v2 %g %g %g material none interior g }\n", v[0][0],
                      v[0][1], v[0][2], v[i1][0], v[i1][1], v[i1][2], v[i2][0], v[i2][1], v[i2][2]);
    }
}

/* shadow_trace_media's one walk (trace_through) against the walk from hit to hit
 * (shadow_steps) for n random shadow rays through the boundaries scene of view v, each
 * from a random medium: the same path state afterwards, bit for bit (the contribution
 * the light brings, or nothing). tally: rays that crossed two or more boundaries, rays
 * blocked, rays the one walk could not answer, boundaries found at the very t of the
 * surface that blocks. */
static void check_shadow_through(const SceneView *v, uint n, uint tally[4])
{
    for (uint i = 0; i < n; i++) {
        Ray r;
        r.o = vrand(-4.5f, 4.5f);
        vec3 to = vrand(-4.5f, 4.5f);
        if (i % 5u == 0u) to = v3_add(v3(1.5f, 1.5f, 0.0f), vrand(-0.1f, 0.1f));   /* through the octahedron's tips */
        r.d = v3_sub(to, r.o);
        r.tmin = 0.0f;
        r.tmax = i % 7u == 0u ? INFINITY : 0.999f;
        PathState ps;
        memset(&ps, 0, sizeof ps);
        ps.shadow_medium = i % (v->params->n_media + 1u);
        ps.shadow_L = v3(0.5f + frand(), 0.5f + frand(), 0.5f + frand());
        ps.radiance = v3(0.25f, 0.5f, 0.75f);
        ps.pixel = i;
        ps.rng_key = 0x9e3779b9u * (i + 1u);
        ps.bounce = i % 4u;
        PathState ref = ps;
        ShadowStretches st;
        st.tr = v3s(1.0f);
        st.len = v3_len(r.d);
        st.rng = 0u;
        st.rng_ready = 0;
        uint steps = shadow_steps(v, &ref, r, &st);
        ref.shadow_L = v3_mul(ref.shadow_L, st.tr);
        shadow_resolve(&ref, v3_is_zero(st.tr));
        uint walks = shadow_trace_media(v, &ps, r);
        ThroughWalk tw;
        trace_through(v, r, &tw);
        for (uint k = 0; k < tw.n; k++) tally[3] += tw.hit.prim != NO_INDEX && tw.crossing[k].t == tw.hit.t;
        CHECK_MSG(memcmp(&ps, &ref, sizeof ps) == 0, "ray %u: the one walk gives (%g %g %g), the walk from hit to "
                  "hit (%g %g %g)", i, ps.radiance.x, ps.radiance.y, ps.radiance.z, ref.radiance.x,
                  ref.radiance.y, ref.radiance.z);
        tally[0] += steps > 2u;
        tally[1] += v3_is_zero(st.tr);
        tally[2] += walks != 1u;
    }
}

/* Shadow rays through media in one walk (trace_through, kernels/medium/transmit.h): the
 * same transmittance as walking from boundary to boundary, through spheres, boxes and
 * triangles that bound media (nested, overlapping, a grid among them), past opaque
 * shapes and a plane, through the BVH and the kd-tree (which finds a triangle in two
 * cells: kept once); most rays cross several boundaries, and all but those through more
 * than THROUGH_MAX of them or through a boundary and a surface at the same t are
 * answered by the one walk. */
static void test_shadow_through(void)
{
    enum { N = 20000 };
    static char text[16384];
    shadow_through_scene_text(text, sizeof text);
    Scene sc;
    scene_init(&sc);
    Error err = { 0 };
    Status st = scene_load_text("shadow-through.scene", text, strlen(text), &sc, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    RenderScene trs;
    KdTree tkd;
    memset(&tkd, 0, sizeof tkd);
    if (st == ST_OK) st = render_scene_prepare(&sc, 1, &trs, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st != ST_OK) {
        scene_free(&sc);
        return;
    }
    SceneView v;
    device_scene_view(&trs.ds, &v);
    CHECK(v.params->has_media && v.params->n_media == 3u && v.params->n_planes == 1u);
    uint tally[4] = { 0, 0, 0, 0 };
    check_shadow_through(&v, N, tally);
    fprintf(stderr, "  trace_through, BVH: %u shadow rays, %u across two boundaries or more, %u blocked, %u "
            "walked from hit to hit (%u at a boundary where a surface blocks)\n", (uint)N, tally[0], tally[1],
            tally[2], tally[3]);
    CHECK(tally[0] > N / 4 && tally[1] > N / 20 && tally[2] > 0u && tally[2] < N / 5 && tally[3] > 0u);
    KdInput in = { sc.spheres, sc.n_spheres, sc.triangles, sc.n_triangles, sc.boxes, sc.n_boxes,
                   sc.revsurfaces, sc.n_revsurfaces, sc.sphere_xforms, sc.n_sphere_xforms, NULL, 0 };
    st = kd_build(&in, 1, &tkd, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        render_scene_use_kdtree(&trs.ds, &tkd);
        device_scene_view(&trs.ds, &v);
        RenderParams p = *v.params;   /* no BVH: the walks take the kd-tree */
        p.n_bvh_nodes = 0u;
        v.params = &p;
        CHECK(trace_tree_kind(&v) == TREE_KD);
        memset(tally, 0, sizeof tally);
        check_shadow_through(&v, N, tally);
        fprintf(stderr, "  trace_through, kd-tree: %u shadow rays, %u across two boundaries or more, %u blocked, "
                "%u walked from hit to hit (%u at a boundary where a surface blocks)\n", (uint)N, tally[0],
                tally[1], tally[2], tally[3]);
        CHECK(tally[0] > N / 4 && tally[2] > 0u && tally[2] < N / 5 && tally[3] > 0u);
    }
    error_clear(&err);
    kd_free(&tkd);
    render_scene_free(&trs);
    scene_free(&sc);
}

/* The trace-only kernels bench_traverse times (kernels/bench/trace.cl): one ray per
 * work-item, two in turns (trace_closest2 / trace_any2), eight one after another (the
 * BVH walk as k_path_lanes calls it) and packets of eight (trace_packet;
 * trace_packet_wide through the BVH), closest hits and occlusion, against the C walk bit
 * for bit, on random rays and on coherent ones (runs of eight from one origin through a
 * small cone, as a camera's neighbouring pixels) over the test scene; the ray count is
 * not a multiple of eight, so the last work-item's run and packet are short. */
static void test_trace_kernels(void)
{
    enum { N = 8000 + 5 };
    Ray *rays = malloc(N * sizeof *rays);
    for (uint i = 0; i < N; i += 8) {
        vec3 o = vrand(-6.0f, 6.0f), d = v3_norm(v3_sub(vrand(-2.0f, 2.0f), o));
        for (uint l = 0; l < 8 && i + l < N; l++) {
            if (i % 16 == 0) {
                rays[i + l] = random_ray();
            } else {
                rays[i + l].o = o;
                rays[i + l].d = v3_norm(v3_add(d, vrand(-0.04f, 0.04f)));
                rays[i + l].tmin = 0.0f;
                rays[i + l].tmax = l == 3 ? 2.0f : INFINITY;
            }
        }
    }
    Hit *ref = malloc(N * sizeof *ref), *dh = malloc(N * sizeof *dh);
    uint *ref_occ = malloc(N * sizeof *ref_occ), *docc = malloc(N * sizeof *docc);
    Hit *wref = malloc(N * sizeof *wref);
    uint *wref_occ = malloc(N * sizeof *wref_occ);
    uint hits = 0, same = 0, n_rev = 0;
    for (uint i = 0; i < N; i++) {
        ref[i] = trace_closest_in(&view, TREE_KD, rays[i]);
        ref_occ[i] = (uint)trace_any_in(&view, TREE_KD, rays[i]);
        wref[i] = trace_closest_in(&view, TREE_BVH, rays[i]);
        wref_occ[i] = (uint)trace_any_in(&view, TREE_BVH, rays[i]);
        hits += ref[i].prim != NO_INDEX;
        /* a surface of revolution's hit is Newton's, started across the interval left
         * (revsurface.h): it depends on the closest hit found before, which the two
         * trees find in different orders; every other primitive's t is exact */
        uint first_rev = view.params->n_spheres + view.params->n_triangles + view.params->n_boxes;
        int rev = (ref[i].prim >= first_rev && ref[i].prim < first_rev + view.params->n_revsurfaces) ||
                  (wref[i].prim >= first_rev && wref[i].prim < first_rev + view.params->n_revsurfaces);
        n_rev += rev;
        same += rev || (memcmp(&wref[i], &ref[i], sizeof ref[i]) == 0 && wref_occ[i] == ref_occ[i]);
    }
    CHECK(hits > N / 4);
    /* both trees find the same closest hit, bit for bit (both follow leaf_test's tie
     * rule; test_kdtree checks more) */
    CHECK_EQ_INT(same, N);
    CHECK(n_rev > 0 && n_rev < N / 4);
    fprintf(stderr, "  the kd-tree and the BVH: the same hit and occlusion for %u rays (%u others hit a surface "
            "of revolution)\n", N - n_rev, n_rev);
    cl_program prog = NULL;
    OclProgramStats ps;
    Error err = { 0 };
    Status st = ocl_program_build_source(cl.ctx, &cl.dev, clpt_bench_kernel_source,
                                         clpt_bench_kernel_source_len, NULL, &prog, &ps, &err);
    CHECK_MSG(st == ST_OK, "%s\n%s", err.msg, err.detail ? err.detail : "");
    fprintf(stderr, "  the traversal kernels %s in %.2f s\n", ps.from_cache ? "loaded from the cache" : "built",
            ps.seconds);
    error_clear(&err);
    cl_mem rb = buffer(N * sizeof *rays, rays), ob = buffer(N * sizeof(Hit), NULL);
    static const struct { const char *name; uint per_item; int any, wide; } ks[] = {
        { "k_trace_closest1", 1, 0, 0 }, { "k_trace_any1", 1, 1, 0 },     { "k_trace_closest", 2, 0, 0 },
        { "k_trace_any", 2, 1, 0 },      { "k_trace_closest8", 8, 0, 0 }, { "k_trace_any8", 8, 1, 0 },
        { "k_trace_closest_wide", 1, 0, 1 }, { "k_trace_any_wide", 1, 1, 1 },
        { "k_trace_closest_lanes", PATH_LANES, 0, 1 }, { "k_trace_any_lanes", PATH_LANES, 1, 1 },
        { "k_trace_closest_wide8", 8, 0, 1 }, { "k_trace_any_wide8", 8, 1, 1 },
    };
    for (size_t j = 0; j < sizeof ks / sizeof ks[0] && st == ST_OK; j++) {
        cl_kernel k = NULL;
        CHECK(ocl_program_kernel(prog, &cl.dev, ks[j].name, &k, &err) == ST_OK);
        error_clear(&err);
        if (!k) continue;
        set_scene_args(k);
        uint n = N;
        SET(k, N_SCENE + 0, rb);
        SET(k, N_SCENE + 1, n);
        SET(k, N_SCENE + 2, ob);
        double t0 = timer_now();
        run(k, (N + ks[j].per_item - 1) / ks[j].per_item);
        double secs = timer_now() - t0;
        uint exact = 0;
        const Hit *rh = ks[j].wide ? wref : ref;
        const uint *ro = ks[j].wide ? wref_occ : ref_occ;
        if (ks[j].any) {
            read_back(ob, N * sizeof *docc, docc);
            for (uint i = 0; i < N; i++) exact += docc[i] == ro[i];
        } else {
            read_back(ob, N * sizeof *dh, dh);
            for (uint i = 0; i < N; i++) exact += memcmp(&dh[i], &rh[i], sizeof rh[i]) == 0;
        }
        fprintf(stderr, "  %s (%u per work-item): %u rays in %.3f s, %u bit-identical to C\n", ks[j].name,
                ks[j].per_item, (uint)N, secs, exact);
        CHECK_EQ_INT(exact, N);
        clReleaseKernel(k);
    }
    if (prog) clReleaseProgram(prog);
    clReleaseMemObject(rb);
    clReleaseMemObject(ob);
    free(rays);
    free(ref);
    free(dh);
    free(ref_occ);
    free(docc);
    free(wref);
    free(wref_occ);
}

/* Shade and shadow: path states at various bounces with random throughput, the hits of
 * random rays (computed once in C and given to both sides). */
static void test_shade_and_shadow(void)
{
    enum { N = 20000 };
    const RenderParams *p = &rs.ds.params;
    PathState *ps = malloc(N * sizeof *ps);
    Ray *rays = malloc(N * sizeof *rays);
    Hit *hits = malloc(N * sizeof *hits);
    uint *queue = malloc(N * sizeof *queue);
    for (uint i = 0; i < N; i++) {
        raygen_path(p, NULL, i % (p->width * p->height), i, &ps[i], &rays[i]);
        if (i % 2) rays[i] = random_ray();
        ps[i].bounce = i % (p->max_depth + 1);
        ps[i].throughput = vrand(0.05f, 1.0f);
        ps[i].radiance = vrand(0.0f, 0.5f);
        ps[i].flags = (i % 3 == 0) ? PATH_SPECULAR : 0u;
        ps[i].bsdf_pdf = frange(0.05f, 1.0f);
        hits[i] = trace_closest(&view, rays[i]);
        queue[i] = i;
    }
    cl_mem pb = buffer(N * sizeof *ps, ps), rb = buffer(N * sizeof *rays, rays), hb = buffer(N * sizeof *hits, hits),
           qb = buffer(N * sizeof *queue, queue), srb = buffer(N * sizeof(Ray), NULL),
           nqb = buffer(N * sizeof(uint), NULL), sqb = buffer(N * sizeof(uint), NULL);
    /* bounce 1 of a wave: the shade kernel counts its shadow rays into count slot 3 and
     * the next queue into slot 4 (entry.cl) */
    cl_uint init_counts[5 * QUEUE_COUNT_STRIDE] = { 0 }, slot = 3;
    init_counts[2 * QUEUE_COUNT_STRIDE] = N;    /* the live paths entering bounce 1 */
    cl_mem cb = buffer(sizeof init_counts, init_counts);
    cl_kernel k = kernel("k_shade");
    set_scene_args(k);
    uint n = N;
    SET(k, N_SCENE + 0, qb);
    SET(k, N_SCENE + 1, n);
    SET(k, N_SCENE + 2, rb);
    SET(k, N_SCENE + 3, hb);
    SET(k, N_SCENE + 4, pb);
    SET(k, N_SCENE + 5, srb);
    SET(k, N_SCENE + 6, nqb);
    SET(k, N_SCENE + 7, sqb);
    SET(k, N_SCENE + 8, cb);
    SET(k, N_SCENE + 9, slot);
    run(k, N + 100);
    PathState *dps = malloc(N * sizeof *dps);
    Ray *drays = malloc(N * sizeof *drays), *dshadow = malloc(N * sizeof *dshadow);
    uint *dnext = malloc(N * sizeof *dnext), *dshq = malloc(N * sizeof *dshq), all_counts[5 * QUEUE_COUNT_STRIDE],
         counts[2];
    read_back(pb, N * sizeof *dps, dps);
    read_back(rb, N * sizeof *drays, drays);
    read_back(srb, N * sizeof *dshadow, dshadow);
    read_back(nqb, N * sizeof *dnext, dnext);
    read_back(sqb, N * sizeof *dshq, dshq);
    read_back(cb, sizeof all_counts, all_counts);
    counts[0] = all_counts[4 * QUEUE_COUNT_STRIDE];
    counts[1] = all_counts[3 * QUEUE_COUNT_STRIDE];

    /* The C side, and the flags each path should have produced. */
    uint *flags = calloc(N, sizeof *flags);
    PathState *cps = malloc(N * sizeof *cps);
    Ray *crays = malloc(N * sizeof *crays), *cshadow = calloc(N, sizeof *cshadow);
    uint n_cont = 0, n_shadow = 0, exact = 0, bad = 0;
    for (uint i = 0; i < N; i++) {
        cps[i] = ps[i];
        crays[i] = rays[i];
        flags[i] = shade_path(&view, &crays[i], hits[i], &cps[i], &cshadow[i]);
        n_cont += (flags[i] & SHADE_CONTINUE) != 0;
        n_shadow += (flags[i] & SHADE_SHADOW) != 0;
    }
    CHECK_EQ_INT(counts[0], n_cont);
    CHECK_EQ_INT(counts[1], n_shadow);
    /* queue membership as sets: every continuing path exactly once */
    uint *seen = calloc(N, sizeof *seen);
    for (uint i = 0; i < counts[0] && i < N; i++) seen[dnext[i]] |= 1u;
    for (uint i = 0; i < counts[1] && i < N; i++) seen[dshq[i]] |= 2u;
    for (uint i = 0; i < N; i++) {
        if (seen[i] != (flags[i] & 3u)) bad++;
        int same = memcmp(&cps[i], &dps[i], sizeof cps[i]) == 0;
        if ((flags[i] & SHADE_CONTINUE) && memcmp(&crays[i], &drays[i], sizeof crays[i])) same = 0;
        if ((flags[i] & SHADE_SHADOW) && memcmp(&cshadow[i], &dshadow[i], sizeof cshadow[i])) same = 0;
        exact += same;
        if (!same && i - exact < 3) {
            report_words("path state", i, &cps[i], &dps[i], sizeof cps[i]);
            report_words("next ray", i, &crays[i], &drays[i], sizeof crays[i]);
            report_words("shadow ray", i, &cshadow[i], &dshadow[i], sizeof cshadow[i]);
        }
        if (!v3_close(cps[i].radiance, dps[i].radiance, 1e-5f) || !v3_close(cps[i].throughput, dps[i].throughput, 1e-5f) ||
            !v3_close(cps[i].shadow_L, dps[i].shadow_L, 1e-5f) || cps[i].bounce != dps[i].bounce ||
            cps[i].flags != dps[i].flags)
            bad++;
        else if ((flags[i] & SHADE_CONTINUE) && !v3_close(crays[i].d, drays[i].d, 1e-5f))
            bad++;
    }
    fprintf(stderr, "  k_shade: %u paths, %u continue, %u shadow rays, %u bit-identical to C\n", (uint)N, n_cont,
            n_shadow, exact);
    CHECK(n_cont > N / 10);
    CHECK(n_shadow > N / 20);
    CHECK_MSG(bad == 0, "%u of %u shaded paths differ", bad, (uint)N);
    CHECK_EQ_INT(exact, N);

    /* k_shadow over the shadow queue the device produced */
    cl_kernel ks = kernel("k_shadow");
    set_scene_args(ks);
    uint ns = N, shadow_slot = slot;             /* an upper bound; the count is on the device */
    SET(ks, N_SCENE + 0, sqb);
    SET(ks, N_SCENE + 1, ns);
    SET(ks, N_SCENE + 2, srb);
    SET(ks, N_SCENE + 3, pb);
    SET(ks, N_SCENE + 4, cb);
    SET(ks, N_SCENE + 5, shadow_slot);
    run(ks, N + 50);
    read_back(pb, N * sizeof *dps, dps);
    uint occluded = 0, sbad = 0, sexact = 0;
    for (uint i = 0; i < N; i++) {
        if (!(flags[i] & SHADE_SHADOW)) continue;
        int occ = trace_any(&view, cshadow[i]);
        occluded += (uint)occ;
        shadow_resolve(&cps[i], occ);
        sexact += memcmp(&cps[i].radiance, &dps[i].radiance, sizeof(vec3)) == 0;
        if (!v3_close(cps[i].radiance, dps[i].radiance, 1e-5f)) sbad++;
    }
    fprintf(stderr, "  k_shadow: %u shadow rays, %u occluded, %u bit-identical to C\n", n_shadow, occluded, sexact);
    CHECK(occluded > 0 && occluded < n_shadow);
    CHECK_MSG(sbad == 0, "%u of %u shadow results differ", sbad, n_shadow);
    CHECK_EQ_INT(sexact, n_shadow);

    free(ps); free(rays); free(hits); free(queue); free(dps); free(drays); free(dshadow);
    free(dnext); free(dshq); free(flags); free(cps); free(crays); free(cshadow); free(seen);
    clReleaseKernel(k);
    clReleaseKernel(ks);
    cl_mem ms[] = { pb, rb, hb, qb, srb, nqb, sqb, cb };
    for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++) clReleaseMemObject(ms[i]);
}

/* Paths that escape, shaded by k_shade with a cube-map background: random directions
 * reach every face, and PoCL gives the C build's bits. */
static void test_shade_cubemap(void)
{
    enum { N = 4096 };
    RenderParams p = rs.ds.params;
    p.bg_type = BG_CUBEMAP;
    p.bg_cubemap = cube_first;
    PathState *ps = malloc(N * sizeof *ps);
    Ray *rays = malloc(N * sizeof *rays);
    Hit *hits = calloc(N, sizeof *hits);
    uint *queue = malloc(N * sizeof *queue);
    for (uint i = 0; i < N; i++) {
        raygen_path(&p, NULL, i % (p.width * p.height), i, &ps[i], &rays[i]);
        rays[i] = random_ray();
        ps[i].throughput = vrand(0.05f, 1.0f);
        hits[i].prim = NO_INDEX;
        queue[i] = i;
    }
    cl_mem parb = buffer(sizeof p, &p), pb = buffer(N * sizeof *ps, ps), rb = buffer(N * sizeof *rays, rays),
           hb = buffer(N * sizeof *hits, hits), qb = buffer(N * sizeof *queue, queue),
           srb = buffer(N * sizeof(Ray), NULL), nqb = buffer(N * sizeof(uint), NULL),
           sqb = buffer(N * sizeof(uint), NULL);
    cl_uint init_counts[5 * QUEUE_COUNT_STRIDE] = { 0 }, slot = 3;
    init_counts[2 * QUEUE_COUNT_STRIDE] = N;    /* the live paths entering bounce 1 */
    cl_mem cb = buffer(sizeof init_counts, init_counts);
    cl_kernel k = kernel("k_shade");
    set_scene_args(k);
    SET(k, 0, parb);
    uint n = N;
    SET(k, N_SCENE + 0, qb);
    SET(k, N_SCENE + 1, n);
    SET(k, N_SCENE + 2, rb);
    SET(k, N_SCENE + 3, hb);
    SET(k, N_SCENE + 4, pb);
    SET(k, N_SCENE + 5, srb);
    SET(k, N_SCENE + 6, nqb);
    SET(k, N_SCENE + 7, sqb);
    SET(k, N_SCENE + 8, cb);
    SET(k, N_SCENE + 9, slot);
    run(k, N);
    PathState *dps = malloc(N * sizeof *dps);
    read_back(pb, N * sizeof *dps, dps);
    SceneView v = view;
    v.params = &p;
    uint exact = 0, bad = 0, lit = 0;
    for (uint i = 0; i < N; i++) {
        PathState c = ps[i];
        Ray r = rays[i], shadow;
        CHECK_EQ_INT(shade_path(&v, &r, hits[i], &c, &shadow), 0);
        lit += v3_max_comp(v3_sub(c.radiance, ps[i].radiance)) > 0.0f;
        exact += memcmp(&c.radiance, &dps[i].radiance, sizeof c.radiance) == 0;
        if (!v3_close(c.radiance, dps[i].radiance, 1e-5f)) bad++;
    }
    fprintf(stderr, "  k_shade (cube-map background): %u escaping paths, %u lit, %u bit-identical to C\n",
            (uint)N, lit, exact);
    CHECK(lit > N / 2);
    CHECK_MSG(bad == 0, "%u of %u escaping paths differ", bad, (uint)N);
    CHECK_EQ_INT(exact, N);
    free(ps); free(rays); free(hits); free(queue); free(dps);
    clReleaseKernel(k);
    cl_mem ms[] = { parb, pb, rb, hb, qb, srb, nqb, sqb, cb };
    for (size_t i = 0; i < sizeof ms / sizeof ms[0]; i++) clReleaseMemObject(ms[i]);
}

/* A wave that starts at pixel 100 of a 600-pixel image and wraps around it three times
 * and a bit: pixels get three or four of its paths. */
static void test_film(void)
{
    uint n_film = 600, first_pixel = 100, n_paths = 2000;
    PathState *ps = calloc(n_paths, sizeof *ps);
    for (uint i = 0; i < n_paths; i++) {
        ps[i].pixel = (first_pixel + i) % n_film;   /* as raygen_path leaves it */
        ps[i].radiance = vrand(0.0f, 3.0f);
        if (i % 97 == 0) ps[i].radiance.x = NAN;           /* dropped, not propagated */
        if (i % 89 == 0) ps[i].radiance.y = 1e30f;         /* clamped */
        if (i % 83 == 0) ps[i].radiance.z = -1.0f;         /* dropped */
    }
    int64_t *film = calloc((size_t)n_film * 3, sizeof *film), *cfilm = calloc((size_t)n_film * 3, sizeof *cfilm);
    for (uint i = 0; i < n_film * 3; i++) film[i] = cfilm[i] = (int64_t)i * 1000;   /* already holds samples */
    cl_mem pb = buffer((size_t)n_paths * sizeof *ps, ps), fb = buffer((size_t)n_film * 3 * sizeof *film, film);
    cl_kernel k = kernel("k_film");
    SET(k, 0, pb);
    SET(k, 1, n_film);
    SET(k, 2, n_paths);
    SET(k, 3, fb);
    run(k, n_film);
    read_back(fb, (size_t)n_film * 3 * sizeof *film, film);
    for (uint i = 0; i < n_paths; i++) film_add(cfilm, (first_pixel + i) % n_film, ps[i].radiance);
    uint bad = 0;
    for (uint i = 0; i < n_film * 3; i++) bad += film[i] != cfilm[i];
    CHECK_MSG(bad == 0, "%u film entries differ (fixed point must match exactly)", bad);
    CHECK(film_fixed(NAN) == 0 && film_fixed(-2.0f) == 0 && film_fixed(INFINITY) == film_fixed(FILM_MAX_SAMPLE));
    CHECK(film_fixed(1.0f) == ((int64_t)1 << FILM_FRAC_BITS));
    free(ps);
    free(film);
    free(cfilm);
    clReleaseKernel(k);
    clReleaseMemObject(pb);
    clReleaseMemObject(fb);
}

/* k_whitted against whitted_sample in C: the classic ray tracer, each auxiliary image
 * and the denoiser's features (through the scene's mirrors and glass), pixel centres
 * and a jittered grid, with and without the adaptive pass's pixel list. */
static void test_whitted(void)
{
    const RenderParams *base = &rs.ds.params;
    uint npix = base->width * base->height, layers = 2, n_all = npix * layers, first_sample = 3;
    /* the adaptive pass's pixel list: the pixels it renders again */
    uint *list = malloc(npix * sizeof *list), n_list = 0;
    for (uint i = 0; i < npix; i++)
        if ((i * 7u) % 5u < 2u) list[n_list++] = i;
    cl_mem lb = buffer(n_list * sizeof *list, list), pb = buffer(n_all * sizeof(PathState), NULL);
    cl_kernel k = kernel("k_whitted");
    struct { uint integrator, strata, listed, cube; const char *name; } modes[] = {
        { INTEGRATOR_WHITTED, 0, 0, 0, "whitted, pixel centres" },
        { INTEGRATOR_WHITTED, 3, 0, 0, "whitted, 3x3 jittered" },
        { INTEGRATOR_WHITTED, 1, 1, 0, "whitted, jittered, a pixel list" },
        { INTEGRATOR_WHITTED, 1, 0, 1, "whitted, cube-map background" },
        { INTEGRATOR_AOV_NORMAL, 0, 0, 0, "normal image" },
        { INTEGRATOR_AOV_DEPTH, 1, 0, 0, "depth image" },
        { INTEGRATOR_AOV_ALBEDO, 0, 0, 0, "albedo image" },
        { INTEGRATOR_FEATURE_NORMAL, 1, 0, 0, "denoiser's normal, through mirrors" },
        { INTEGRATOR_FEATURE_ALBEDO, 3, 0, 1, "denoiser's albedo, through mirrors" },
        { INTEGRATOR_FEATURE_EMISSION, 1, 0, 1, "denoiser's emission, the path's camera rays" },
    };
    for (size_t m = 0; m < sizeof modes / sizeof modes[0]; m++) {
        RenderParams p = *base;
        p.integrator = modes[m].integrator;
        p.strata = modes[m].strata;
        p.pixel_list_size = modes[m].listed ? n_list : 0u;
        uint n_pixels = modes[m].listed ? n_list : npix, n = n_pixels * layers;
        p.sample_offset = 5;
        if (modes[m].cube) {
            p.bg_type = BG_CUBEMAP;
            p.bg_cubemap = cube_first;
        }
        cl_mem parb = buffer(sizeof p, &p);
        cl_uint zero = 0;
        cl_mem cb = buffer(sizeof zero, &zero);
        set_scene_args(k);
        SET(k, 0, parb);
        SET(k, SCENE_BUF_pixel_list, lb);
        uint first_pixel = 0;
        SET(k, N_SCENE + 0, first_pixel);
        SET(k, N_SCENE + 1, first_sample);
        SET(k, N_SCENE + 2, n_pixels);
        SET(k, N_SCENE + 3, n);
        SET(k, N_SCENE + 4, pb);
        SET(k, N_SCENE + 5, cb);
        size_t global = (n + 63) / 64 * 64, local = 64;
        cl_int rc = clEnqueueNDRangeKernel(cl.q, k, 1, NULL, &global, &local, 0, NULL, NULL);
        CHECK_MSG(rc == CL_SUCCESS, "clEnqueueNDRangeKernel: %s", ocl_error_name(rc));
        CHECK(clFinish(cl.q) == CL_SUCCESS);
        PathState *dp = malloc(n * sizeof *dp);
        cl_uint drays = 0;
        read_back(pb, n * sizeof *dp, dp);
        read_back(cb, sizeof drays, &drays);
        SceneView v = view;
        v.params = &p;
        v.pixel_list = list;
        uint exact = 0, bad = 0, crays = 0, lit = 0;
        for (uint i = 0; i < n; i++) {
            uint r = 0, pixel = batch_pixel(&v, i % n_pixels);
            vec3 L = whitted_sample(&v, pixel, first_sample + i / n_pixels, &r);
            if (dp[i].pixel != pixel) bad++;   /* k_film adds the sample there */
            crays += r;
            lit += v3_max_comp(L) > 0.0f;
            exact += memcmp(&L, &dp[i].radiance, sizeof L) == 0;
            if (!v3_close(L, dp[i].radiance, 1e-5f)) bad++;
        }
        fprintf(stderr, "  k_whitted (%s): %u samples, %u rays, %u non-black, %u bit-identical to C\n",
                modes[m].name, n, crays, lit, exact);
        CHECK_MSG(bad == 0, "%s: %u of %u samples differ", modes[m].name, bad, n);
        CHECK_EQ_INT(drays, crays);
        CHECK(lit > n / 4);
        free(dp);
        clReleaseMemObject(parb);
        clReleaseMemObject(cb);
    }
    clReleaseKernel(k);
    clReleaseMemObject(lb);
    clReleaseMemObject(pb);
    free(list);
}

/* Builds a test kernel, SOURCE, as the renderer builds its own: the same options (so
 * -cl-fp32-correctly-rounded-divide-sqrt where the device has it), kernels/ on the
 * include path. Returns NULL (and has failed the test) if it does not build. */
static cl_program build_test_program(const char *source)
{
    char dir[] = "/tmp/clpt-test-kernel-XXXXXX", path[128], inc[1200], cwd[1024];
    CHECK(mkdtemp(dir) != NULL);
    CHECK(getcwd(cwd, sizeof cwd) != NULL);
    snprintf(path, sizeof path, "%s/entry.cl", dir);
    snprintf(inc, sizeof inc, "-I %s/kernels", cwd);
    FILE *f = fopen(path, "w");
    CHECK(f != NULL);
    if (!f) return NULL;
    fputs(source, f);
    fclose(f);
    cl_program prog = NULL;
    OclProgramStats ps;
    Error err = {0};
    Status st = ocl_program_build(cl.ctx, &cl.dev, dir, inc, &prog, &ps, &err);
    CHECK_MSG(st == ST_OK, "%s\n%s", err.msg, err.detail ? err.detail : "");
    error_clear(&err);
    unlink(path);
    rmdir(dir);
    return st == ST_OK ? prog : NULL;
}

/* The arithmetic the bit-for-bit guarantee rests on, checked on the device itself:
 * a * b + c rounded twice (FP_CONTRACT OFF in compat.h: no fused multiply-add),
 * products into the subnormal range kept (no flush to zero), and / and sqrt
 * correctly rounded. A device that breaks one of these cannot give the C twin's bits. */
static void test_fp_semantics(void)
{
    cl_program prog = build_test_program(
        "#include \"util/compat.h\"\n"
        "__kernel void k_fp(__global const float *in, __global float *out, uint n)\n"
        "{\n"
        "    uint i = (uint)get_global_id(0);\n"
        "    if (i >= n) return;\n"
        "    float x = in[3u * i], y = in[3u * i + 1u], z = in[3u * i + 2u];\n"
        "    out[4u * i] = x * y + z;\n"
        "    out[4u * i + 1u] = (x * 0x1p-70f) * (y * 0x1p-60f);\n"
        "    out[4u * i + 2u] = x / y;\n"
        "    out[4u * i + 3u] = k_sqrt(k_fabs(x * z));\n"
        "}\n");
    if (!prog) return;
    enum { N = 50000 };
    float *in = malloc(3 * N * sizeof *in), *out = malloc(4 * N * sizeof *out);
    for (uint i = 0; i < 3 * N; i++) in[i] = frand() * 4.0f - 2.0f;
    cl_mem ib = buffer(3 * N * sizeof *in, in), ob = buffer(4 * N * sizeof *out, NULL);
    cl_kernel k = NULL;
    Error err = {0};
    CHECK(ocl_program_kernel(prog, &cl.dev, "k_fp", &k, &err) == ST_OK);
    uint n = N;
    SET(k, 0, ib);
    SET(k, 1, ob);
    SET(k, 2, n);
    run(k, N);
    read_back(ob, 4 * N * sizeof *out, out);
    uint same[4] = {0}, fused = 0, subnormal = 0;
    for (uint i = 0; i < N; i++) {
        float x = in[3 * i], y = in[3 * i + 1], z = in[3 * i + 2];
        float c[4] = { x * y + z, (x * 0x1p-70f) * (y * 0x1p-60f), x / y, sqrtf(fabsf(x * z)) };
        for (int j = 0; j < 4; j++) same[j] += memcmp(&c[j], &out[4 * i + j], sizeof c[j]) == 0;
        float f = fmaf(x, y, z);
        fused += memcmp(&c[0], &f, sizeof f) != 0 && memcmp(&f, &out[4 * i], sizeof f) == 0;
        subnormal += c[1] != 0.0f && fabsf(c[1]) < FLT_MIN;
    }
    fprintf(stderr, "  a*b+c %u, tiny products %u (%u subnormal), x/y %u, sqrt %u of %u bit-identical to C;"
            " %u fused\n", same[0], same[1], subnormal, same[2], same[3], (uint)N, fused);
    for (int j = 0; j < 4; j++) CHECK_EQ_INT(same[j], N);
    CHECK(subnormal > N / 10);
    free(in);
    free(out);
    clReleaseKernel(k);
    clReleaseMemObject(ib);
    clReleaseMemObject(ob);
    clReleaseProgram(prog);
}

/* The functions of kmath.h that stand in for libm, through a test kernel built from a
 * folder holding just an entry.cl that includes kmath.h: the same bits as the C build
 * on every input, subnormals, zeros and the extremes included. */
static void test_kmath(void)
{
    cl_program prog = build_test_program("#include \"util/kmath.h\"\n"
          "__kernel void k_math(__global const float *in, __global float *out, uint n)\n"
          "{\n"
          "    uint i = (uint)get_global_id(0);\n"
          "    if (i >= n) return;\n"
          "    float x = in[2u * i], y = in[2u * i + 1u], s, c;\n"
          "    k_sincos(y, &s, &c);\n"
          "    out[8u * i + 0u] = k_log2(x);\n"
          "    out[8u * i + 1u] = k_exp2(y);\n"
          "    out[8u * i + 2u] = k_pow(x, k_fabs(y));\n"
          "    out[8u * i + 3u] = k_atan2(y, x - 1.0f);\n"
          "    out[8u * i + 4u] = k_acos(x - 1.0f);\n"
          "    out[8u * i + 5u] = k_srgb_to_linear(k_fmin(x, 1.0f));\n"
          "    out[8u * i + 6u] = s + c;\n"
          "    out[8u * i + 7u] = k_smoothstep(0.2f, 0.7f, x) + k_cbrt(x);\n"
          "}\n");
    if (!prog) return;
    Error err = {0};
    enum { N = 40000 };
    float *in = malloc(2 * N * sizeof *in), *dout = malloc(8 * N * sizeof *dout);
    for (uint i = 0; i < N; i++) {
        float x = frand() * 2.0f;
        if (i % 7 == 0) x = k_exp2(frange(-149.0f, 20.0f));       /* subnormal to large */
        if (i % 101 == 0) x = (float)(i % 3);                      /* 0, 1, 2 exactly */
        in[2 * i] = x;
        in[2 * i + 1] = frange(-160.0f, 160.0f);
        if (i % 3 == 0) in[2 * i + 1] = frange(0.0f, 300.0f);   /* Phong exponents */
    }
    cl_mem ib = buffer(2 * N * sizeof *in, in), ob = buffer(8 * N * sizeof *dout, NULL);
    cl_kernel k = NULL;
    CHECK(ocl_program_kernel(prog, &cl.dev, "k_math", &k, &err) == ST_OK);
    uint n = N;
    SET(k, 0, ib);
    SET(k, 1, ob);
    SET(k, 2, n);
    run(k, N);
    read_back(ob, 8 * N * sizeof *dout, dout);
    uint exact = 0;
    for (uint i = 0; i < N; i++) {
        float x = in[2 * i], y = in[2 * i + 1], s, c;
        k_sincos(y, &s, &c);
        float cv[8] = { k_log2(x), k_exp2(y), k_pow(x, k_fabs(y)), k_atan2(y, x - 1.0f), k_acos(x - 1.0f),
                        k_srgb_to_linear(k_fmin(x, 1.0f)), s + c, k_smoothstep(0.2f, 0.7f, x) + k_cbrt(x) };
        exact += memcmp(cv, dout + 8 * i, sizeof cv) == 0;
    }
    fprintf(stderr, "  kmath (log2 exp2 pow atan2 acos sRGB sincos cbrt): %u of %u inputs bit-identical to C\n",
            exact, (uint)N);
    CHECK_EQ_INT(exact, N);
    free(in);
    free(dout);
    clReleaseKernel(k);
    clReleaseMemObject(ib);
    clReleaseMemObject(ob);
    clReleaseProgram(prog);
}

/* The BSDF dispatch of kernels/bsdf/bsdf.h (bsdf_eval and bsdf_sample over every material
 * type, the microfacet lobes of microfacet.h under them), through a test kernel built
 * from a folder holding just an entry.cl that includes bsdf.h: the same bits as the C
 * build for random directions, grazing and back-facing ones included; and the shading
 * normal bsdf_normal makes valid for each (bent for the grazing views). */
enum { BSDF_IN = 17, BSDF_OUT = 16 };

static void bsdf_reference(const Material *mats, uint n_mats, uint i, const float *in, float *out)
{
    Material m = mats[i % n_mats];
    vec3 d = v3(in[0], in[1], in[2]), ns = v3(in[3], in[4], in[5]), ng = v3(in[6], in[7], in[8]);
    vec3 wi = v3(in[14], in[15], in[16]);
    int front = in[9] > 0.5f;
    float pdf;
    vec3 f = bsdf_eval(m, m.albedo, d, ns, front, wi, &pdf);
    BsdfSample bs = bsdf_sample(m, m.albedo, d, ns, ng, front, in[10], in[11], in[12], in[13]);
    vec3 nv = bsdf_normal(m, d, ns, ng);
    float r[BSDF_OUT] = { f.x, f.y, f.z, pdf, bs.wi.x, bs.wi.y, bs.wi.z, bs.weight.x, bs.weight.y, bs.weight.z,
                          bs.pdf, (float)bs.specular, (float)bs.transmitted, nv.x, nv.y, nv.z };
    memcpy(out, r, sizeof r);
}

static void test_bsdf(void)
{
    cl_program prog = build_test_program("#include \"bsdf/bsdf.h\"\n"
          "__kernel void k_bsdf(__global const Material *mats, uint n_mats, __global const float *in,\n"
          "                     __global float *out, uint n)\n"
          "{\n"
          "    uint i = (uint)get_global_id(0);\n"
          "    if (i >= n) return;\n"
          "    __global const float *x = in + 17u * i;\n"
          "    Material m = mats[i % n_mats];\n"
          "    vec3 d = v3(x[0], x[1], x[2]), ns = v3(x[3], x[4], x[5]), ng = v3(x[6], x[7], x[8]);\n"
          "    vec3 wi = v3(x[14], x[15], x[16]);\n"
          "    int front = x[9] > 0.5f;\n"
          "    float pdf;\n"
          "    vec3 f = bsdf_eval(m, m.albedo, d, ns, front, wi, &pdf);\n"
          "    BsdfSample bs = bsdf_sample(m, m.albedo, d, ns, ng, front, x[10], x[11], x[12], x[13]);\n"
          "    vec3 nv = bsdf_normal(m, d, ns, ng);\n"
          "    __global float *o = out + 16u * i;\n"
          "    o[0] = f.x; o[1] = f.y; o[2] = f.z; o[3] = pdf;\n"
          "    o[4] = bs.wi.x; o[5] = bs.wi.y; o[6] = bs.wi.z;\n"
          "    o[7] = bs.weight.x; o[8] = bs.weight.y; o[9] = bs.weight.z; o[10] = bs.pdf;\n"
          "    o[11] = (float)bs.specular; o[12] = (float)bs.transmitted;\n"
          "    o[13] = nv.x; o[14] = nv.y; o[15] = nv.z;\n"
          "}\n");
    if (!prog) return;
    Error err = {0};
    /* every material type, the microfacet ones at several roughnesses */
    Material mats[] = { material_diffuse(v3(0.7f, 0.5f, 0.3f)), material_metal(v3s(0.9f), 0.3f),
                        material_dielectric(1.5f), material_phong(v3s(0.4f), v3s(0.4f), 40.0f),
                        material_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.6f, 2.6f, 2.4f), 0.0f),
                        material_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.6f, 2.6f, 2.4f), 0.3f),
                        material_conductor_f0(v3(0.9f, 0.8f, 0.5f), 0.8f),
                        material_conductor(v3(1.5f, 0.96f, 0.6f), v3(7.8f, 6.7f, 5.5f), 0.5f),
                        material_dielectric(1.5f), material_dielectric(1.33f), material_dielectric(1.5f),
                        material_dielectric(1.5f), material_principled(v3(0.8f, 0.5f, 0.3f), 0.0f, 0.4f),
                        material_principled(v3(0.9f, 0.7f, 0.4f), 1.0f, 0.0f),
                        material_principled(v3(0.5f, 0.8f, 0.9f), 0.3f, 0.6f),
                        material_principled(v3(0.6f, 0.6f, 0.7f), 0.0f, 0.5f),
                        material_coated_diffuse(v3(0.8f, 0.5f, 0.3f), 0.0f),
                        material_coated_diffuse(v3(0.3f, 0.6f, 0.9f), 0.4f),
                        material_coated_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.6f, 2.6f, 2.4f), 0.3f, 0.2f),
                        material_coated_conductor(v3(0.2f, 0.9f, 1.1f), v3(3.6f, 2.6f, 2.4f), 0.0f, 0.0f),
                        material_principled(v3(0.7f, 0.8f, 0.4f), 0.0f, 0.5f),
                        material_principled(v3(0.9f, 0.9f, 0.9f), 0.2f, 0.3f) };
    /* KHR_materials_diffuse_transmission: on a solid, and on a thin sheet with the
     * transmission and sheen lobes too */
    mats[19].diffuse_transmission = 0.6f;
    mats[19].diffuse_transmission_color = v3(0.9f, 0.4f, 0.2f);
    mats[20].diffuse_transmission = 1.0f;
    mats[20].transmission = 0.3f;
    mats[20].sheen_color = v3s(0.5f);
    mats[20].sheen_roughness = 0.6f;
    mats[20].flags |= MAT_THIN;
    /* coated: a scattering medium in two of them, one conductor all smooth (deltas) */
    mats[17].layer_albedo = v3(0.9f, 0.6f, 0.3f);
    mats[17].layer_thickness = 0.4f;
    mats[17].layer_g = 0.3f;
    mats[17].layer_samples = 2;
    mats[18].layer_albedo = v3s(0.5f);
    mats[18].layer_g = -0.2f;
    mats[18].base_anisotropy = 0.5f;
    mats[14].transmission = 0.7f;
    /* KHR_materials_specular and _sheen over a transmitting solid */
    mats[15].transmission = 0.5f;
    mats[15].specular_factor = 0.7f;
    mats[15].specular_color = v3(1.4f, 0.8f, 0.3f);
    mats[15].sheen_color = v3(0.9f, 0.5f, 0.2f);
    mats[15].sheen_roughness = 0.45f;
    mats[14].clearcoat = 1.0f;
    mats[14].clearcoat_roughness = 0.2f;
    mats[7].anisotropy = 0.7f;
    mats[8].roughness = 0.2f;
    mats[9].roughness = 0.7f;
    mats[10].flags |= MAT_THIN;
    mats[11].flags |= MAT_THIN;
    mats[11].roughness = 0.4f;
    mats[3].reflective = v3s(0.1f);
    mats[3].transparent = v3s(0.3f);
    uint n_mats = sizeof mats / sizeof mats[0];
    enum { N = 24000 };
    float *in = malloc(BSDF_IN * N * sizeof *in), *dout = malloc(BSDF_OUT * N * sizeof *dout);
    for (uint i = 0; i < N; i++) {
        float *x = in + BSDF_IN * i;
        vec3 ng = v3_norm(vrand(-1.0f, 1.0f));
        vec3 ns = v3_norm(v3_madd(ng, vrand(-0.3f, 0.3f), 1.0f));
        vec3 d = v3_norm(vrand(-1.0f, 1.0f));
        if (v3_dot(d, ng) > 0.0f) d = v3_neg(d);
        if (i % 5 == 0) d = v3_norm(v3_madd(v3_cross(ng, v3(0.3f, 0.7f, 0.1f)), ng, -1e-4f));   /* grazing */
        vec3 wi = v3_norm(vrand(-1.0f, 1.0f));
        float v[BSDF_IN] = { d.x, d.y, d.z, ns.x, ns.y, ns.z, ng.x, ng.y, ng.z, (float)(i / 7 % 2),
                             frand(), frand(), frand(), frand(), wi.x, wi.y, wi.z };
        memcpy(x, v, sizeof v);
    }
    cl_mem mb = buffer(sizeof mats, mats), ib = buffer(BSDF_IN * N * sizeof *in, in),
           ob = buffer(BSDF_OUT * N * sizeof *dout, NULL);
    cl_kernel k = NULL;
    CHECK(ocl_program_kernel(prog, &cl.dev, "k_bsdf", &k, &err) == ST_OK);
    uint n = N;
    SET(k, 0, mb);
    SET(k, 1, n_mats);
    SET(k, 2, ib);
    SET(k, 3, ob);
    SET(k, 4, n);
    run(k, N);
    read_back(ob, BSDF_OUT * N * sizeof *dout, dout);
    uint exact = 0, nonzero = 0, bent = 0;
    for (uint i = 0; i < N; i++) {
        float cv[BSDF_OUT];
        bsdf_reference(mats, n_mats, i, in + BSDF_IN * i, cv);
        bent += memcmp(&cv[13], in + BSDF_IN * i + 3, 3 * sizeof *cv) != 0;
        int same = memcmp(cv, dout + BSDF_OUT * i, sizeof cv) == 0;
        exact += same;
        if (!same && i + 1 - exact <= 3) {
            const Material *m = &mats[i % n_mats];
            fprintf(stderr, "    input %u: material %u (type %u, roughness %g), u_lobe %a\n", i, i % n_mats,
                    (uint)m->type, (double)m->roughness, (double)in[BSDF_IN * i + 10]);
            report_words("bsdf outputs (f, pdf, wi, weight, pdf, specular, transmitted, normal)", i, cv,
                         dout + BSDF_OUT * i, sizeof cv);
        }
        nonzero += cv[3] > 0.0f;
    }
    fprintf(stderr, "  bsdf_eval / bsdf_sample / bsdf_normal: %u of %u inputs bit-identical to C (%u with a "
            "density, %u normals bent)\n", exact, (uint)N, nonzero, bent);
    CHECK_EQ_INT(exact, N);
    CHECK(nonzero > N / 4);
    CHECK(bent > N / 50);
    free(in);
    free(dout);
    clReleaseKernel(k);
    clReleaseMemObject(mb);
    clReleaseMemObject(ib);
    clReleaseMemObject(ob);
    clReleaseProgram(prog);
}

/* An offline OpenCL C compiler must see the kernels as OpenCL C: compat.h keys on
 * __OPENCL_C_VERSION__, which clang -x cl defines (it does not define
 * __OPENCL_VERSION__, which compat.h once tested, and then took the C11 branch).
 * Skipped, and said so, where no clang is installed. */
static void test_offline_compiler_sees_opencl(void)
{
    if (system("command -v clang >/dev/null 2>&1") != 0) {
        fprintf(stderr, "  SKIP: no clang to compile the kernels offline\n");
        return;
    }
    int rc = system("clang -x cl -cl-std=CL1.2 -Xclang -finclude-default-header -fsyntax-only -Ikernels "
                    "kernels/entry.cl");
    CHECK_MSG(rc == 0, "clang -x cl -cl-std=CL1.2 kernels/entry.cl: status %d", rc);
}

int main(void)
{
    RUN(test_offline_compiler_sees_opencl);
    build_scene();
    build_lanes_scene();
    cl.ok = setup_opencl();
    if (!cl.ok) {
        /* make test installs PoCL: no OpenCL device is a failure, not a skip */
        harness_failed++;
        fprintf(stderr, "FAIL no OpenCL device to compare against\n");
        return harness_report();
    }
    RUN(test_layout);
    RUN(test_raygen);
    RUN(test_path_kernel);
    RUN(test_path_kernel_listed);
    RUN(test_path_lanes_kernel);
    RUN(test_intersect);
    RUN(test_flight_walk);
    RUN(test_shadow_through);
    RUN(test_shade_and_shadow);
    RUN(test_shade_cubemap);
    RUN(test_film);
    RUN(test_whitted);
    RUN(test_kmath);
    RUN(test_fp_semantics);
    RUN(test_bsdf);
    /* last: the only test that builds a second program (the traversal kernels) */
    RUN(test_trace_kernels);
    for (int i = 0; i < N_SCENE; i++) {
        clReleaseMemObject(cl.scene[i]);
        clReleaseMemObject(lanes_bufs[i]);
    }
    clReleaseProgram(cl.prog);
    clReleaseCommandQueue(cl.q);
    clReleaseContext(cl.ctx);
    render_scene_free(&rs);
    render_scene_free(&lanes_rs);
    kd_free(&kd);
    scene_free(&scene);
    scene_free(&lanes_scene);
    return harness_report();
}
