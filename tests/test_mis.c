/*
 * test_mis.c — the path integrator's light sampling: light sampling alone, BSDF sampling
 * alone and their combination by multiple importance sampling converge to the same
 * image for area lights over a diffuse and over a glossy (Phong) floor, which checks
 * that the Phong BRDF, its sampling and its density agree with each other; delta lights
 * give the path integrator the same direct light as the classic ray tracer; the Phong
 * BRDF never reflects more than it receives; the Sobol sampler's light choice by the
 * light pair's first coordinate (light_sample_in's reuse) is the explicit choice and
 * keeps the pair's strata; the two halves of a quad lamp are found and sampled as one
 * parallelogram, uniformly.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "util/kmath.h"
#include "light/lights.h"
#include "geom/surface.h"
#include "render_util.h"

enum { W = 32, H = 24, BLOCK = 8 };

/* A floor of material `floor_mat`, a sphere light and a quad light, seen from above at
 * an angle; direct light only (depth 1) so that the estimators are the two strategies
 * and nothing else. */
static void area_scene(Scene *s, Material floor_mat, uint spp)
{
    scene_init(s);
    s->image.width = W;
    s->image.height = H;
    s->image.spp = spp;
    s->image.max_depth = 1;
    s->image.seed = 11;
    s->camera.from = v3(0.0f, 3.0f, 5.0f);
    s->camera.at = v3(0.0f, 0.0f, 0.0f);
    s->camera.vfov = 50.0f;
    uint fm, lamp, quad_lamp;
    scene_add_material(s, "floor", floor_mat, &fm, NULL);
    scene_add_material(s, "lamp", material_emissive(v3(6.0f, 5.0f, 4.0f)), &lamp, NULL);
    Material ql = material_emissive(v3(2.0f, 3.0f, 4.0f));
    ql.flags = MAT_TWO_SIDED;
    scene_add_material(s, "quad", ql, &quad_lamp, NULL);
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = v3(0.0f, 1.0f, 0.0f);
    pl.material = fm;
    scene_add_plane(s, pl, NULL);
    Sphere sp = { v3(-1.0f, 1.5f, 0.0f), 0.8f, lamp, NO_INDEX, 0, 0 };
    scene_add_sphere(s, sp, NULL);
    Triangle a = { v3(0.3f, 1.5f, -1.5f), quad_lamp, v3(2.3f, 1.5f, -1.5f), NO_INDEX, v3(2.3f, 1.5f, 0.5f), NO_INDEX };
    Triangle b = { v3(0.3f, 1.5f, -1.5f), quad_lamp, v3(2.3f, 1.5f, 0.5f), NO_INDEX, v3(0.3f, 1.5f, 0.5f), NO_INDEX };
    scene_add_triangle(s, a, NULL);
    scene_add_triangle(s, b, NULL);
}

/* area_scene with a box lamp (1 x 2 x 3, emitting outward) in the air as a third light. */
static void area_scene_with_box(Scene *s, Material floor_mat, uint spp)
{
    area_scene(s, floor_mat, spp);
    uint box_lamp;
    scene_add_material(s, "box lamp", material_emissive(v3(3.0f, 2.0f, 1.0f)), &box_lamp, NULL);
    Box b = { v3(-2.5f, 0.4f, -2.0f), box_lamp, v3(-1.5f, 2.4f, 1.0f), NO_INDEX };
    scene_add_box(s, b, NULL);
}

/* s prepared for rendering (its tree and light list, render_scene_prepare) in *rs, and
 * the kernels' view of it in *v, for tests that call the kernel functions directly. */
static void prepared_view(Scene *s, RenderScene *rs, SceneView *v)
{
    Error err = {0};
    CHECK(render_scene_prepare(s, 0, rs, &err) == ST_OK);
    error_clear(&err);
    device_scene_view(&rs->ds, v);
}

/* Mean of each BLOCK x BLOCK block (12 of them) and of the whole image. */
static void block_means(const float *rgb, double blocks[12], double *mean)
{
    memset(blocks, 0, 12 * sizeof *blocks);
    *mean = 0.0;
    for (uint y = 0; y < H; y++)
        for (uint x = 0; x < W; x++) {
            double v = (rgb[3 * (y * W + x)] + rgb[3 * (y * W + x) + 1] + rgb[3 * (y * W + x) + 2]) / 3.0;
            blocks[(y / BLOCK) * (W / BLOCK) + x / BLOCK] += v / (BLOCK * BLOCK);
            *mean += v / (W * H);
        }
}

/* The three strategies on one scene. Light sampling alone is noisy where a glossy lobe
 * reflects a light (its blocks get the looser tolerance); the image means and BSDF
 * sampling against MIS are held tight. */
static void check_strategies_agree(const char *name, Material floor_mat, uint spp, double tol_mean,
                                   double tol_block, double tol_light_block)
{
    Scene s;
    area_scene(&s, floor_mat, spp);
    float *img[3];
    double blocks[3][12], mean[3];
    const char *names[3] = { "MIS", "light sampling", "BSDF sampling" };
    Error err = {0};
    for (uint m = 0; m < 3; m++) {
        img[m] = malloc(W * H * 3 * sizeof *img[m]);
        Status st = render_util_rgb_mis(&s, m, "scalar", img[m], &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        block_means(img[m], blocks[m], &mean[m]);
    }
    double worst[3] = { 0.0, 0.0, 0.0 };
    for (uint m = 1; m < 3; m++)
        for (int b = 0; b < 12; b++) {
            double ref = blocks[0][b];
            double rel = fabs(blocks[m][b] - ref) / (ref > 0.05 ? ref : 0.05);
            if (rel > worst[m]) worst[m] = rel;
        }
    fprintf(stderr, "  %s, %u spp: image mean %s %.4f, %s %.4f, %s %.4f; worst 8x8 block difference to MIS: "
            "light %.1f%%, BSDF %.1f%%\n", name, spp, names[0], mean[0], names[1], mean[1], names[2], mean[2],
            100.0 * worst[1], 100.0 * worst[2]);
    CHECK(mean[0] > 0.05);
    CHECK(fabs(mean[1] - mean[0]) < tol_mean * mean[0]);
    CHECK(fabs(mean[2] - mean[0]) < tol_mean * mean[0]);
    CHECK(fabs(mean[1] - mean[2]) < tol_mean * mean[0]);
    CHECK(worst[1] < tol_light_block);
    CHECK(worst[2] < tol_block);
    for (int m = 0; m < 3; m++) free(img[m]);
    scene_free(&s);
    error_clear(&err);
}

static void test_mis_diffuse(void)
{
    check_strategies_agree("diffuse floor", material_diffuse(v3(0.7f, 0.6f, 0.5f)), 512, 0.015, 0.08, 0.08);
}

/* Light sampling only evaluates the Phong BRDF; BSDF sampling depends on its sampling
 * and density too: their agreement checks the three against each other. */
static void test_mis_phong(void)
{
    check_strategies_agree("Phong floor (kd 0.3, ks 0.6, n 20)",
                           material_phong(v3(0.3f, 0.3f, 0.3f), v3(0.6f, 0.6f, 0.6f), 20.0f), 512, 0.015, 0.12, 0.2);
    check_strategies_agree("Phong floor (kd 0.1, ks 0.8, n 200)",
                           material_phong(v3(0.1f, 0.1f, 0.1f), v3(0.8f, 0.8f, 0.8f), 200.0f), 512, 0.025, 0.2, 0.35);
}

/* The microfacet lobes (kernels/bsdf/microfacet.h, principled.h) the same way: light
 * sampling evaluates bsdf_eval, BSDF sampling uses bsdf_sample and its density. */
static void test_mis_microfacet(void)
{
    Material gold = material_conductor(v3(0.17f, 0.35f, 1.5f), v3(3.1f, 2.7f, 1.9f), 0.4f);
    check_strategies_agree("rough gold floor (roughness 0.4)", gold, 512, 0.02, 0.15, 0.3);
    gold.roughness = 0.6f;
    gold.anisotropy = 0.7f;
    check_strategies_agree("anisotropic gold floor (roughness 0.6, anisotropy 0.7)", gold, 512, 0.02, 0.15, 0.3);
    Material glass = material_dielectric(1.5f);
    glass.roughness = 0.4f;
    check_strategies_agree("rough glass floor (roughness 0.4)", glass, 512, 0.03, 0.2, 0.35);
    Material pm = material_principled(v3(0.7f, 0.4f, 0.2f), 0.3f, 0.5f);
    pm.clearcoat = 0.7f;
    pm.clearcoat_roughness = 0.3f;
    check_strategies_agree("principled floor (metallic 0.3, roughness 0.5, clearcoat 0.7)", pm, 512, 0.02, 0.15, 0.3);
}

/* The three strategies with a box lamp too: its face is chosen from the light pair's
 * first coordinate after the light (light_sample_area's reuse). */
static void test_mis_box_lamp(void)
{
    Scene s;
    area_scene_with_box(&s, material_diffuse(v3(0.7f, 0.6f, 0.5f)), 512);
    float *img[3];
    double blocks[3][12], mean[3];
    Error err = {0};
    for (uint m = 0; m < 3; m++) {
        img[m] = malloc(W * H * 3 * sizeof *img[m]);
        CHECK(render_util_rgb_mis(&s, m, "scalar", img[m], &err) == ST_OK);
        block_means(img[m], blocks[m], &mean[m]);
    }
    fprintf(stderr, "  with a box lamp, 512 spp: image mean MIS %.4f, light sampling %.4f, BSDF sampling %.4f\n",
            mean[0], mean[1], mean[2]);
    CHECK(fabs(mean[1] - mean[0]) < 0.015 * mean[0]);
    CHECK(fabs(mean[2] - mean[0]) < 0.015 * mean[0]);
    for (int m = 0; m < 3; m++) free(img[m]);
    scene_free(&s);
    error_clear(&err);
}

/* light_sample with reuse (the Sobol sampler's next-event estimation) over a stratified
 * sweep of the pair's first coordinate u1, from a point on the floor: every sample of
 * the sphere is bit for bit the one the explicit choice gives (u1 choosing, its rest in
 * u1's place), and every sample of the quad lamp's two triangles is the parallelogram's
 * point for that rest (types.h); each light is chosen for its share of the sweep to
 * within one stratum; the box lamp's faces get their shares of its samples by area (the
 * face chosen from the rest of u1, the rest of that placing the point), and every point
 * lies on the face chosen. */
static void test_light_choice_reuses_u1(void)
{
    enum { N = 6000 };
    Scene s;
    area_scene_with_box(&s, material_diffuse(v3s(0.5f)), 1);
    RenderScene rs;
    SceneView v;
    prepared_view(&s, &rs, &v);
    uint n_lights = rs.ds.params.n_lights;
    CHECK_EQ_INT(n_lights, 4);
    uint chosen[4] = { 0, 0, 0, 0 }, faces[6] = { 0, 0, 0, 0, 0, 0 }, box_samples = 0;
    uint differ = 0, off_face = 0, light_of_box = NO_INDEX, quad_samples = 0;
    /* the quad lamp's two triangles are lights 1 and 2, paired (types.h) */
    CHECK_EQ_INT(v.lights[1].quad, LIGHT_QUAD_FIRST);
    CHECK_EQ_INT(v.lights[2].quad, LIGHT_QUAD_SECOND);
    CHECK(v.lights[1].pick_pdf == v.lights[2].pick_pdf);
    Box bx = s.boxes[0];
    vec3 ref = v3(0.5f, 0.0f, 2.0f);
    for (uint i = 0; i < N; i++) {
        float u1 = ((float)i + 0.5f) / (float)N, u2 = (float)((i * 2654435769u) >> 8) * 5.9604645e-8f;
        float rest;
        uint li = light_choose(&v, u1, &rest);
        chosen[li]++;
        LightSample a, b;
        int ok_a = light_sample(&v, ref, 1, 1, 0.0f, u1, u2, &a);
        if (v.lights[li].prim >= rs.ds.params.n_spheres + rs.ds.params.n_triangles) {
            light_of_box = li;
            if (!ok_a) continue;
            box_samples++;
            /* which face: the coordinate on a face plane, with the side */
            vec3 q = a.p;
            int f = q.x == bx.lo.x ? 0 : q.x == bx.hi.x ? 1 : q.y == bx.lo.y ? 2 : q.y == bx.hi.y ? 3
                  : q.z == bx.lo.z ? 4 : q.z == bx.hi.z ? 5 : -1;
            if (f < 0 || q.x < bx.lo.x || q.x > bx.hi.x || q.y < bx.lo.y || q.y > bx.hi.y || q.z < bx.lo.z ||
                q.z > bx.hi.z) {
                off_face++;
                continue;
            }
            faces[f]++;
            continue;
        }
        Light l = v.lights[li];
        if (l.quad != LIGHT_QUAD_NONE) {
            /* half of the quad lamp: the rest of u1 runs along the parallelogram's edge
             * (types.h), and the density is the chosen half's */
            quad_samples++;
            float sq = (l.quad == LIGHT_QUAD_SECOND ? 0.5f : 0.0f) + 0.5f * rest;
            vec3 want = v3_add(l.position, v3_add(v3_scale(l.direction, sq), v3_scale(l.intensity, u2)));
            if (!ok_a || memcmp(&a.p, &want, sizeof want) || a.pdf != light_pdf(&v, li, ref, a.p, a.n)) differ++;
            continue;
        }
        int ok_b = light_sample(&v, ref, 1, 0, u1, rest, u2, &b);
        if (ok_a != ok_b || (ok_a && (memcmp(&a.p, &b.p, sizeof a.p) || a.pdf != b.pdf))) differ++;
    }
    fprintf(stderr, "  reuse sweep of %d: lights chosen %u %u %u %u (pick pdf %.4f %.4f %.4f %.4f); box faces %u %u "
            "%u %u %u %u of %u; %u differ from the explicit choice, %u off the box\n", N, chosen[0], chosen[1],
            chosen[2], chosen[3], (double)v.lights[0].pick_pdf, (double)v.lights[1].pick_pdf,
            (double)v.lights[2].pick_pdf, (double)v.lights[3].pick_pdf, faces[0], faces[1], faces[2], faces[3],
            faces[4], faces[5], box_samples, differ, off_face);
    CHECK_EQ_INT(differ, 0);
    CHECK_EQ_INT(off_face, 0);
    CHECK(quad_samples > N / 16);     /* the quad has 11% of the choices */
    for (uint li = 0; li < n_lights; li++) CHECK(fabs(chosen[li] - N * (double)v.lights[li].pick_pdf) <= 1.0);
    CHECK(light_of_box != NO_INDEX);
    /* faces by area (1 x 2 x 3: x faces 6, y faces 3, z faces 2 of 22), each side half;
     * samples of faces turned away from ref are dropped, so only chosen faces that
     * face ref count: compare each visible face with its expected share of the box's
     * choices, within two strata */
    double area[6] = { 6.0, 6.0, 3.0, 3.0, 2.0, 2.0 };
    for (int f = 0; f < 6; f++)
        if (faces[f]) CHECK(fabs(faces[f] - chosen[light_of_box] * area[f] / 22.0) <= 2.0);
    render_scene_free(&rs);
    scene_free(&s);
}

/* A scene of two triangle lights of material `mat_b` for the second, the first's
 * corners (0,2,0) (1,2,0) (1,2,1) facing down, the second's given; its light list. */
static void two_triangle_lights(Scene *s, vec3 q0, vec3 q1, vec3 q2, int same_material)
{
    scene_init(s);
    uint lamp, other;
    scene_add_material(s, "lamp", material_emissive(v3s(4.0f)), &lamp, NULL);
    scene_add_material(s, "other", material_emissive(v3s(4.0f)), &other, NULL);
    Triangle a = { v3(0.0f, 2.0f, 0.0f), lamp, v3(1.0f, 2.0f, 1.0f), NO_INDEX, v3(1.0f, 2.0f, 0.0f), NO_INDEX };
    Triangle b = { q0, same_material ? lamp : other, q1, NO_INDEX, q2, NO_INDEX };
    scene_add_triangle(s, a, NULL);
    scene_add_triangle(s, b, NULL);
    Error err = {0};
    CHECK(scene_prepare_lights(s, &err) == ST_OK);
    error_clear(&err);
}

/* Which pairs of triangle lights are sampled as one parallelogram: the two halves of a
 * quad, split along either diagonal and with their corners in any order, are; a kite
 * (the reflected corner off by 1%), a pair of two materials and a pair whose second
 * half is wound the other way are not. */
static void test_quad_lights_pair(void)
{
    static const struct { vec3 q0, q1, q2; int same, pair; const char *what; } cases[] = {
        { { 0, 2, 0 }, { 0, 2, 1 }, { 1, 2, 1 }, 1, 1, "the other half" },
        { { 1, 2, 1 }, { 0, 2, 0 }, { 0, 2, 1 }, 1, 1, "the other half, corners rotated" },
        { { 0, 2, 0 }, { 0, 2, 1.01f }, { 1, 2, 1 }, 1, 0, "a kite" },
        { { 0, 2, 0 }, { 0, 2, 1 }, { 1, 2, 1 }, 0, 0, "another material" },
        { { 0, 2, 0 }, { 1, 2, 1 }, { 0, 2, 1 }, 1, 0, "wound the other way" },
        { { 1, 2, 0 }, { 2, 2, 1 }, { 1, 2, 1 }, 1, 0, "sharing an edge but not the diagonal" },
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        Scene s;
        two_triangle_lights(&s, cases[i].q0, cases[i].q1, cases[i].q2, cases[i].same);
        CHECK_EQ_INT(s.n_lights, 2);
        uint want0 = cases[i].pair ? LIGHT_QUAD_FIRST : LIGHT_QUAD_NONE;
        uint want1 = cases[i].pair ? LIGHT_QUAD_SECOND : LIGHT_QUAD_NONE;
        CHECK_MSG(s.lights[0].quad == want0 && s.lights[1].quad == want1, "%s: quad marks %u %u", cases[i].what,
                  s.lights[0].quad, s.lights[1].quad);
        if (cases[i].pair) {
            CHECK(s.lights[0].pick_pdf == 0.5f && s.lights[1].pick_pdf == 0.5f);
            /* the parallelogram is the two triangles: its corners are theirs */
            Light l = s.lights[0];
            vec3 far = v3_add(l.position, v3_add(l.direction, l.intensity));
            CHECK(v3_dot(v3_cross(l.direction, l.intensity), v3_cross(l.direction, l.intensity)) > 0.99f);
            CHECK(far.y == 2.0f && fabsf(fabsf(far.x - l.position.x) - 1.0f) < 1e-6f &&
                  fabsf(fabsf(far.z - l.position.z) - 1.0f) < 1e-6f);
        }
        scene_free(&s);
    }
}

/* The quad lamp of area_scene sampled through its two lights with the Sobol sampler's
 * reuse: points uniform over the whole parallelogram (chi-square over 8 x 8 cells of
 * its edge coordinates, from random pairs), all on it, and each sample's density the
 * lamp's uniform area density as light_pdf gives it. */
static void test_quad_lamp_samples_uniformly(void)
{
    enum { N = 64000, G = 8 };
    Scene s;
    area_scene(&s, material_diffuse(v3s(0.5f)), 1);
    RenderScene rs;
    SceneView v;
    prepared_view(&s, &rs, &v);
    Light q = v.lights[1];
    CHECK_EQ_INT(q.quad, LIGHT_QUAD_FIRST);
    double counts[G * G] = { 0 };
    uint n = 0, off = 0, bad_pdf = 0, bad_normal = 0;
    vec3 ref = v3(0.5f, 0.0f, 2.0f);
    float lo = v.lights[0].cdf, hi = v.lights[2].cdf;     /* the quad's share of u1 */
    uint32_t h = 12345u;
    double e11 = v3_dot(q.direction, q.direction), e22 = v3_dot(q.intensity, q.intensity);
    double e12 = v3_dot(q.direction, q.intensity), det = e11 * e22 - e12 * e12;
    for (uint i = 0; i < N; i++) {
        h = h * 1664525u + 1013904223u;
        float a = (float)(h >> 8) * 5.9604645e-8f;
        h = h * 1664525u + 1013904223u;
        float u2 = (float)(h >> 8) * 5.9604645e-8f;
        float u1 = lo + (hi - lo) * a;
        if (!(u1 < hi)) continue;
        LightSample ls;
        if (!light_sample(&v, ref, 1, 1, 0.0f, u1, u2, &ls)) continue;
        float rest;
        uint li = light_choose(&v, u1, &rest);
        if (li != 1u && li != 2u) continue;
        n++;
        vec3 d = v3_sub(ls.p, q.position);
        double d1 = v3_dot(d, q.direction), d2 = v3_dot(d, q.intensity);
        double sq = (d1 * e22 - d2 * e12) / det, tq = (d2 * e11 - d1 * e12) / det;
        if (!(sq >= -1e-6 && sq <= 1.0 + 1e-6 && tq >= -1e-6 && tq <= 1.0 + 1e-6) || fabsf(ls.p.y - 1.5f) > 1e-6f) {
            off++;
            continue;
        }
        int cs = (int)(sq * G), ct = (int)(tq * G);
        counts[(cs < G ? cs : G - 1) * G + (ct < G ? ct : G - 1)] += 1.0;
        /* uniform over the quad: choice of the pair times 1/area, in solid angle */
        vec3 to = v3_sub(ls.p, ref);
        double dist2 = v3_dot(to, to), cos_l = fabs(v3_dot(ls.n, to)) / sqrt(dist2);
        double want = (double)(q.pick_pdf * 2.0f) / (2.0 * q.area) * dist2 / cos_l;
        if (fabs(ls.pdf - want) > 1e-5 * want || ls.pdf != light_pdf(&v, li, ref, ls.p, ls.n)) bad_pdf++;
        /* the normal kept in the light is the one a BSDF-sampled ray finds on the lamp
         * (surface_at), bit for bit, so both strategies' densities agree for MIS */
        Ray r = { ref, 0.0f, ls.wi, INFINITY };
        Hit hit = { ls.dist, v.lights[li].prim, 0.25f, 0.25f, NO_INDEX, 0u, 0u, 0u };
        Surface sf = surface_at(&v, r, hit);
        if (memcmp(&sf.ng, &ls.n, sizeof ls.n)) bad_normal++;
    }
    double chi2 = 0.0, expect = (double)(n - off) / (G * G);
    for (int c = 0; c < G * G; c++) chi2 += (counts[c] - expect) * (counts[c] - expect) / expect;
    fprintf(stderr, "  quad lamp: %u samples, %u off the quad, %u with another density; chi-square %.1f over %d cells\n",
            n, off, bad_pdf, chi2, G * G);
    CHECK(n > N / 2);
    CHECK_EQ_INT(off, 0);
    CHECK_EQ_INT(bad_pdf, 0);
    CHECK_EQ_INT(bad_normal, 0);
    CHECK(chi2 < 103.4);   /* 63 degrees of freedom, p = 0.001 */
    render_scene_free(&rs);
    scene_free(&s);
}

/* A directional light: the path integrator's next-event estimate is exact (one light,
 * one direction), so every pixel must be kd/pi x E cos, as the classic ray tracer says. */
static void test_delta_lights_match_whitted(void)
{
    Scene s;
    area_scene(&s, material_diffuse(v3(0.7f, 0.6f, 0.5f)), 4);
    s.n_spheres = 0;
    s.n_triangles = 0;                              /* only the floor */
    Light dl = light_default(LIGHT_DIRECTIONAL);
    dl.direction = v3_norm(v3(0.3f, -1.0f, 0.2f));
    dl.intensity = v3s(2.0f);
    scene_add_light(&s, dl, NULL);
    float *path = malloc(W * H * 3 * sizeof *path), *whitted = malloc(W * H * 3 * sizeof *whitted);
    Error err = {0};
    CHECK(render_util_rgb_mis(&s, MIS_BOTH, "scalar", path, &err) == ST_OK);
    s.integrator = INTEGRATOR_WHITTED;
    CHECK(render_util_rgb_mis(&s, MIS_BOTH, TEST_OPENCL, whitted, &err) == ST_OK);
    double cos_t = 1.0 / sqrt(0.09 + 1.0 + 0.04), want = 0.7 / M_PI * 2.0 * cos_t, worst = 0.0;
    for (uint i = 0; i < W * H; i++) {
        if (path[3 * i] == 0.0f) continue;          /* sky */
        double e = fabs(path[3 * i] - want) + fabs(whitted[3 * i] - want);
        if (e > worst) worst = e;
    }
    CHECK(worst < 1e-5);
    /* a point light: the path tracer's jittered pixels average to the whitted centres */
    s.n_delta_lights = 0;
    Light pl = light_default(LIGHT_POINT);
    pl.position = v3(0.5f, 2.0f, 1.0f);
    pl.intensity = v3s(5.0f);
    scene_add_light(&s, pl, NULL);
    s.image.spp = 16;
    s.integrator = INTEGRATOR_PATH;
    CHECK(render_util_rgb_mis(&s, MIS_BOTH, "scalar", path, &err) == ST_OK);
    s.integrator = INTEGRATOR_WHITTED;
    CHECK(render_util_rgb_mis(&s, MIS_BOTH, "scalar", whitted, &err) == ST_OK);
    double sp = 0.0, sw = 0.0;
    for (uint i = 0; i < W * H * 3; i++) {
        sp += path[i];
        sw += whitted[i];
    }
    fprintf(stderr, "  point light: path mean %.5f, whitted mean %.5f\n", sp / (W * H * 3), sw / (W * H * 3));
    CHECK(fabs(sp - sw) < 0.01 * sw);
    free(path);
    free(whitted);
    scene_free(&s);
    error_clear(&err);
}

/* Among delta lights the choice is made at the shading point (light_choose_delta):
 * area_scene's two lamps, then a sun, a point light and a spot aimed away from ref. Over
 * a stratified sweep of the choice number, with and without reuse of u1: the lamps keep
 * their power shares; the spot, which sends nothing to ref, is never chosen; the sun
 * and the point light share their group's power in proportion to what each sends to
 * ref, each sample's density saying so; and the mean of Le / pdf over the delta samples
 * is what the three send together (the estimate is unbiased). */
static void test_delta_light_choice_at_point(void)
{
    enum { N = 20000 };
    Scene s;
    area_scene(&s, material_diffuse(v3s(0.5f)), 1);
    Light sun = light_default(LIGHT_DIRECTIONAL);
    sun.direction = v3_norm(v3(0.3f, -1.0f, 0.2f));
    sun.intensity = v3(3.0f, 3.0f, 2.0f);
    Light pt = light_default(LIGHT_POINT);
    pt.position = v3(0.5f, 2.0f, 1.0f);
    pt.intensity = v3s(5.0f);
    Light spot = light_default(LIGHT_SPOT);
    spot.position = v3(0.0f, 3.0f, 0.0f);
    spot.direction = v3(0.0f, 1.0f, 0.0f);
    spot.intensity = v3s(50.0f);
    CHECK(scene_add_light(&s, sun, NULL) == ST_OK);
    CHECK(scene_add_light(&s, pt, NULL) == ST_OK);
    CHECK(scene_add_light(&s, spot, NULL) == ST_OK);
    RenderScene rs;
    SceneView v;
    prepared_view(&s, &rs, &v);
    uint first = rs.ds.params.n_area_lights;
    CHECK_EQ_INT(rs.ds.params.n_lights, first + 3u);
    vec3 ref = v3(0.2f, 0.0f, 0.3f);
    vec3 to = v3_sub(pt.position, ref);
    double w_sun = 8.0, w_pt = 15.0 / v3_dot(to, to), group = v.lights[first + 2].cdf - v.lights[first - 1].cdf;
    double want_sum = 3.0 + 5.0 / v3_dot(to, to);   /* the red channel of what the three send */
    for (int reuse = 0; reuse <= 1; reuse++) {
        uint n_sun = 0, n_pt = 0, n_spot = 0, n_area = 0, bad_pdf = 0;
        double sum = 0.0;
        for (uint i = 0; i < N; i++) {
            float u = ((float)i + 0.5f) / (float)N, u2 = (float)((i * 2654435769u) >> 8) * 5.9604645e-8f;
            LightSample ls;
            int ok = reuse ? light_sample(&v, ref, 1, 1, 0.0f, u, u2, &ls)
                           : light_sample(&v, ref, 1, 0, u, u2, 0.5f, &ls);
            if (!ok) continue;
            if (!ls.delta) {
                n_area++;
                continue;
            }
            int is_sun = !(ls.dist < INFINITY), is_pt = !is_sun && ls.p.y == 2.0f;
            n_sun += is_sun;
            n_pt += is_pt;
            n_spot += !is_sun && !is_pt;
            double want = group * (is_sun ? w_sun : w_pt) / (w_sun + w_pt);
            if (fabs(ls.pdf - want) > 1e-5 * want) bad_pdf++;
            sum += ls.Le.x / ls.pdf;
        }
        double mean = sum / N;
        fprintf(stderr, "  delta lights chosen at the point (reuse %d): sun %u, point %u, spot %u, area %u of %d "
                "(group %.4f; sun's share by what it sends %.4f); %u with another density; mean Le/pdf %.5f, "
                "want %.5f\n", reuse, n_sun, n_pt, n_spot, n_area, N, group, w_sun / (w_sun + w_pt), bad_pdf, mean,
                want_sum);
        CHECK_EQ_INT(n_spot, 0);
        CHECK_EQ_INT(bad_pdf, 0);
        CHECK(fabs(n_sun - N * group * w_sun / (w_sun + w_pt)) <= 2.0);
        CHECK(fabs(n_pt - N * group * w_pt / (w_sun + w_pt)) <= 2.0);
        CHECK(fabs(mean - want_sum) < 1e-3 * want_sum);
    }
    render_scene_free(&rs);
    scene_free(&s);
}

/* A Phong sphere in a white furnace (background 1, no lights): with kd + ks <= 1 it can
 * only darken; kd 1 alone reflects everything. */
static void test_phong_energy(void)
{
    const float mats[3][3] = { { 1.0f, 0.0f, 1.0f }, { 0.5f, 0.5f, 10.0f }, { 1.0f, 1.0f, 50.0f } };
    for (int i = 0; i < 3; i++) {
        Scene s;
        scene_init(&s);
        s.image.width = W;
        s.image.height = H;
        s.image.spp = 64;
        s.image.max_depth = 64;
        s.camera.from = v3(0.0f, 0.0f, 3.0f);
        s.camera.vfov = 25.0f;
        s.bg_color = s.bg_zenith = v3s(1.0f);
        Sphere sp = { v3s(0.0f), 1.0f, 0, NO_INDEX, 0, 0 };
        scene_add_material(&s, "p", material_phong(v3s(mats[i][0]), v3s(mats[i][1]), mats[i][2]), &sp.material, NULL);
        scene_add_sphere(&s, sp, NULL);
        float *rgb = malloc(W * H * 3 * sizeof *rgb);
        Error err = {0};
        CHECK(render_util_rgb_mis(&s, MIS_BOTH, "scalar", rgb, &err) == ST_OK);
        double mean = 0.0;
        for (uint k = 0; k < W * H * 3; k++) mean += rgb[k] / (W * H * 3);
        fprintf(stderr, "  furnace, kd %g ks %g n %g: mean %.4f\n", (double)mats[i][0], (double)mats[i][1],
                (double)mats[i][2], mean);
        if (i == 0) CHECK(fabs(mean - 1.0) < 0.01);
        else CHECK(mean < 1.0 + 0.01 && mean > 0.5);
        free(rgb);
        scene_free(&s);
    }
}

int main(void)
{
    RUN(test_mis_diffuse);
    RUN(test_mis_phong);
    RUN(test_mis_microfacet);
    RUN(test_mis_box_lamp);
    RUN(test_light_choice_reuses_u1);
    RUN(test_quad_lights_pair);
    RUN(test_quad_lamp_samples_uniformly);
    RUN(test_delta_lights_match_whitted);
    RUN(test_delta_light_choice_at_point);
    RUN(test_phong_energy);
    return harness_report();
}
