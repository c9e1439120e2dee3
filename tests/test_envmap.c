/*
 * test_envmap.c — the environment map (kernels/light/envmap.h, host/scene/env_dist.c,
 * host/io/exr.c): its orientation, its sampling against its density (chi-square over
 * the map's pixels), the density against light_pdf, a furnace (diffuse spheres in a
 * constant map render albedo x the map), MIS against light sampling alone and BSDF
 * sampling alone, PoCL against the scalar device bit for bit, the whitted integrator's
 * view of it, and the shared DWA-compressed EXR maps. Run from the project root.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "harness.h"
#include "render_util.h"
#include "io/exr.h"
#include "io/texture.h"
#include "light/lights.h"
#include "scene/env_dist.h"
#include "texture_util.h"

enum { W = 32, H = 24 };

/* Adds a W x H float map (rgb, 3 floats a pixel) to the scene as its environment. */
static void set_map(Scene *s, const float *rgb, uint w, uint h, float intensity, float rotate)
{
    size_t n = (size_t)w * h * 3u;
    uint *bits = malloc(n * sizeof *bits);
    memcpy(bits, rgb, n * sizeof *bits);
    uint index = test_image_texture(s, bits, w, h, TEX_FLOAT);
    free(bits);
    CHECK(index != NO_INDEX);
    Error err = { 0 };
    CHECK_MSG(scene_set_envmap(s, index, intensity, rotate, &err) == ST_OK, "%s", err.msg);
}

/* A map with structure: a smooth gradient, a bright "sun" of a few pixels, and a black
 * band (pixels light sampling must never pick). */
static float *structured_map(uint w, uint h)
{
    float *m = malloc((size_t)w * h * 3u * sizeof *m);
    for (uint y = 0; y < h; y++)
        for (uint x = 0; x < w; x++) {
            float *p = m + 3u * (y * w + x);
            p[0] = 0.2f + 0.8f * (float)x / (float)w;
            p[1] = 0.3f + 0.5f * (float)y / (float)h;
            p[2] = 0.5f;
            if (x >= w / 2 && x < w / 2 + 3 && y == h / 4) p[0] = p[1] = p[2] = 40.0f;
            if (y == h - 2) p[0] = p[1] = p[2] = 0.0f;
        }
    return m;
}

/* ------------------------------------------------------------------ statistics */

/* log Gamma(a) by Lanczos (g = 7, 9 terms), for the chi-square p-value. */
static double log_gamma(double a)
{
    static const double c[9] = { 0.99999999999980993, 676.5203681218851, -1259.1392167224028, 771.32342877765313,
                                 -176.61502916214059, 12.507343278686905, -0.13857109526572012,
                                 9.9843695780195716e-6, 1.5056327351493116e-7 };
    a -= 1.0;
    double x = c[0], t = a + 7.5;
    for (int i = 1; i < 9; i++) x += c[i] / (a + i);
    return 0.5 * log(2.0 * M_PI) + (a + 0.5) * log(t) - t + log(x);
}

/* The regularised upper incomplete gamma Q(a, x): series below a + 1, Lentz's
 * continued fraction above (Numerical Recipes' gammq). */
static double gamma_q(double a, double x)
{
    if (x <= 0.0) return 1.0;
    double lg = log_gamma(a);
    if (x < a + 1.0) {
        double sum = 1.0 / a, term = sum;
        for (int n = 1; n < 1000; n++) {
            term *= x / (a + n);
            sum += term;
            if (fabs(term) < fabs(sum) * 1e-15) break;
        }
        return 1.0 - sum * exp(-x + a * log(x) - lg);
    }
    double b = x + 1.0 - a, cc = 1.0 / 1e-300, d = 1.0 / b, hh = d;
    for (int i = 1; i < 1000; i++) {
        double an = -i * (i - a);
        b += 2.0;
        d = an * d + b;
        if (fabs(d) < 1e-300) d = 1e-300;
        cc = b + an / cc;
        if (fabs(cc) < 1e-300) cc = 1e-300;
        d = 1.0 / d;
        double del = d * cc;
        hh *= del;
        if (fabs(del - 1.0) < 1e-15) break;
    }
    return exp(-x + a * log(x) - lg) * hh;
}

/* ------------------------------------------------------------------ sampling */

/* The direction of the centre of pixel (x, y) and back: what the docs promise (first
 * row up, u = 0 looking along -z, u = 1/4 along +x, u = 1/2 along +z), turned by
 * `rotate` right-handedly about +y. */
static void test_orientation(void)
{
    enum { MW = 8, MH = 4 };
    float rgb[MW * MH * 3];
    for (uint i = 0; i < MW * MH; i++) rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = (float)i + 1.0f;
    struct { float rotate; vec3 d; uint x, y; } cases[] = {
        { 0.0f, { 0.0f, 0.0f, -1.0f }, 0, 2 },      /* u = 0 (the edge; rounding may give 7) */
        { 0.0f, { 1.0f, -0.1f, 0.0f }, 2, 2 },      /* u = 1/4 */
        { 0.0f, { 0.0f, 0.2f, 1.0f }, 4, 1 },       /* u = 1/2 */
        { 0.0f, { -1.0f, 0.1f, 0.0f }, 6, 1 },      /* u = 3/4 */
        { 0.0f, { 0.1f, 1.0f, 0.1f }, 3, 0 },       /* straight up: the first row */
        { 0.0f, { 0.1f, -1.0f, 0.1f }, 3, 3 },      /* straight down: the last */
        { 90.0f, { 1.0f, -0.1f, 0.0f }, 4, 2 },     /* rotated: the map's +z is the world's +x */
        { -90.0f, { 0.0f, 0.2f, 1.0f }, 2, 1 },     /* the map's +x is the world's +z */
    };
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        Scene s;
        scene_init(&s);
        set_map(&s, rgb, MW, MH, 2.0f, cases[c].rotate);
        RenderScene rs;
        Error err = { 0 };
        CHECK(render_scene_prepare(&s, 1, &rs, &err) == ST_OK);
        SceneView v;
        device_scene_view(&rs.ds, &v);
        vec3 d = cases[c].d;
        if (c == 0) d.x = 1e-3f;   /* just right of the seam: column 0 */
        vec3 L = env_radiance(&v, d);
        float want = 2.0f * (float)(cases[c].y * MW + cases[c].x + 1);
        CHECK_MSG(L.x == want, "case %zu: radiance %g, want pixel (%u, %u) x 2 = %g", c, (double)L.x, cases[c].x,
                  cases[c].y, (double)want);
        render_scene_free(&rs);
        scene_free(&s);
    }
}

/* Directions from env_sample, binned by the pixel env_pixel puts them in, against
 * each pixel's probability computed here in double from the map (luminance x
 * sin(theta) at the row's centre; with `mis`, the compensated distribution's:
 * luminance less its mean over the sphere, at least 0, x sin(theta)); every sample's
 * radiance and light_sample pdf are what env_radiance and light_pdf_env give its
 * direction (the density to rounding: the sample keeps its pixel and sin(theta), the
 * others find them from the direction); the density integrates to 1 over the sphere. */
static void check_sampling(float rotate, int mis)
{
    enum { MW = 24, MH = 12, N = 400000 };
    float *rgb = structured_map(MW, MH);
    if (mis) {
        /* a dimmer sun: the compensated distribution keeps about half the map, not the
         * sun alone, and the chi-square has pixels to count */
        for (uint i = 0; i < MW * MH * 3u; i++)
            if (rgb[i] == 40.0f) rgb[i] = 2.0f;
    }
    Scene s;
    scene_init(&s);
    set_map(&s, rgb, MW, MH, 1.5f, rotate);
    RenderScene rs;
    Error err = { 0 };
    CHECK(render_scene_prepare(&s, 1, &rs, &err) == ST_OK);
    CHECK_EQ_INT(rs.ds.params.n_lights, 1);
    CHECK_EQ_INT(rs.ds.params.bg_light, 0);
    SceneView v;
    device_scene_view(&rs.ds, &v);
    Texture tx = v.textures[rs.ds.params.bg_cubemap];
    /* the structured map has a compensated distribution; where it starts */
    CHECK_EQ_INT(rs.ds.params.env_mis_dist, (int)env_dist_floats(MW, MH));
    double prob[MW * MH], total = 0.0, floor = 0.0, sin_sum = 0.0;
    for (int pass = mis ? 0 : 1; pass < 2; pass++) {
        /* pass 0 (mis): the mean luminance over the sphere, the compensation's floor */
        for (uint y = 0; y < MH; y++)
            for (uint x = 0; x < MW; x++) {
                const float *p = rgb + 3u * (y * MW + x);
                double lum = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2], st = sin(M_PI * (y + 0.5) / MH);
                if (pass == 0) {
                    floor += lum * st;
                    sin_sum += st;
                    continue;
                }
                prob[y * MW + x] = (lum > floor * (1.0 + 1e-6) ? lum - floor * (1.0 + 1e-6) : 0.0) * st;
                total += prob[y * MW + x];
            }
        if (pass == 0) floor /= sin_sum;
    }
    uint zero_pixels = 0;
    for (uint i = 0; i < MW * MH; i++) zero_pixels += prob[i] == 0.0;
    static uint count[MW * MH];
    memset(count, 0, sizeof count);
    uint rng = 1u, pdf_mismatch = 0, rejected = 0;
    double worst_rel = 0.0;
    for (uint i = 0; i < N; i++) {
        float u[3];
        for (int k = 0; k < 3; k++) {
            rng = rng * 1664525u + 1013904223u;
            u[k] = (float)(rng >> 8) * (1.0f / 16777216.0f);
        }
        LightSample ls;
        if (!light_sample(&v, v3s(0.0f), mis, 0, u[0], u[1], u[2], &ls)) {
            /* a point on a pole (sin(theta) 0) has density 0 and is dropped: rare */
            rejected++;
            continue;
        }
        uint px, py;
        float ct;
        env_pixel(&rs.ds.params, tx, ls.wi, &px, &py, &ct);
        count[py * MW + px]++;
        /* the sample's density is its pixel's, with sin(theta) of its (u, v); the
         * direction's density finds the pixel and sin(theta) again from the direction:
         * the same to rounding, unless rounding put the direction across the pixel's
         * edge (rare) */
        float pdf_dir = light_pdf_env(&v, ls.wi, mis);
        double rel = fabs((double)ls.pdf - (double)pdf_dir) / (double)pdf_dir;
        vec3 Le_dir = env_radiance(&v, ls.wi);
        if (!(rel <= 1e-5) || ls.Le.x != Le_dir.x || ls.Le.y != Le_dir.y || ls.Le.z != Le_dir.z) pdf_mismatch++;
        else if (rel > worst_rel) worst_rel = rel;
    }
    /* chi-square over the pixels, those expecting fewer than 5 samples pooled */
    double chi2 = 0.0, pool_exp = 0.0, pool_obs = 0.0;
    int dof = -1;
    uint in_black = 0;
    for (uint i = 0; i < MW * MH; i++) {
        double e = (double)N * prob[i] / total;
        if (prob[i] == 0.0) in_black += count[i];
        if (e < 5.0) {
            pool_exp += e;
            pool_obs += count[i];
            continue;
        }
        chi2 += (count[i] - e) * (count[i] - e) / e;
        dof++;
    }
    if (pool_exp > 0.0) {
        chi2 += (pool_obs - pool_exp) * (pool_obs - pool_exp) / pool_exp;
        dof++;
    }
    double p_value = gamma_q(0.5 * dof, 0.5 * chi2);
    /* the density over the sphere: its mean over uniform directions times 4 pi */
    double integral = 0.0;
    enum { M = 1000000 };
    for (uint i = 0; i < M; i++) {
        rng = rng * 1664525u + 1013904223u;
        float u1 = (float)(rng >> 8) * (1.0f / 16777216.0f);
        rng = rng * 1664525u + 1013904223u;
        float u2 = (float)(rng >> 8) * (1.0f / 16777216.0f);
        integral += env_pdf(&v, sample_sphere_dir(u1, u2), mis);
    }
    integral *= 4.0 * M_PI / M;
    fprintf(stderr, "  %s, rotate %g: chi-square %.1f with %d degrees of freedom, p-value %.3f; %u samples in "
            "the %u pixels of probability 0; %u radiances or densities differ from the direction's (densities by "
            "more than 1e-5; the others by %.1e at most); %u samples rejected; density integrates to %.4f\n",
            mis ? "compensated" : "full", (double)rotate, chi2, dof, p_value, in_black, zero_pixels, pdf_mismatch,
            worst_rel, rejected, integral);
    /* the compensated distribution leaves the pixels below the mean out */
    CHECK(mis ? zero_pixels > MW * MH / 4 && zero_pixels < MW * MH * 3 / 4 : zero_pixels == MW);
    CHECK(rejected < N / 10000);
    CHECK(p_value > 1e-3);
    CHECK_EQ_INT(in_black, 0);
    CHECK(pdf_mismatch <= N / 10000);
    CHECK_NEAR(integral, 1.0, 0.01);
    render_scene_free(&rs);
    scene_free(&s);
    free(rgb);
}

static void test_sampling_matches_density(void) { check_sampling(0.0f, 0); }
static void test_sampling_matches_density_rotated(void) { check_sampling(37.0f, 0); }
static void test_compensated_sampling_matches_density(void) { check_sampling(0.0f, 1); }
static void test_compensated_sampling_matches_density_rotated(void) { check_sampling(37.0f, 1); }

/* ------------------------------------------------------------------ images */

/* A sphere of albedo `albedo` filling the middle of the view, nothing else, under map
 * `rgb` (mw x mh). */
static void sphere_scene(Scene *s, const float *rgb, uint mw, uint mh, float albedo, uint spp, uint depth)
{
    scene_init(s);
    s->image.width = W;
    s->image.height = H;
    s->image.spp = spp;
    s->image.max_depth = depth;
    s->image.seed = 5;
    s->camera.from = v3(0.0f, 0.5f, 4.0f);
    s->camera.at = v3(0.0f, 0.0f, 0.0f);
    s->camera.vfov = 40.0f;
    uint m;
    scene_add_material(s, "ball", material_diffuse(v3s(albedo)), &m, NULL);
    Sphere sp = { v3(0.0f, 0.0f, 0.0f), 1.0f, m, NO_INDEX, 0, 0 };
    scene_add_sphere(s, sp, NULL);
    set_map(s, rgb, mw, mh, 1.0f, 0.0f);
}

/* A convex diffuse sphere in a constant map of radiance L sees only the map: every
 * pixel on it is albedo x L, and every pixel off it is L exactly. */
static void check_furnace(float albedo)
{
    float rgb[8 * 4 * 3];
    for (int i = 0; i < 8 * 4 * 3; i++) rgb[i] = 0.8f;
    Scene s;
    sphere_scene(&s, rgb, 8, 4, albedo, 64, 4);
    /* a constant map is at its mean everywhere: no compensated distribution */
    CHECK(s.n_env_cdf == env_dist_floats(8, 4) && s.env_mis_dist == 0u);
    Film f;
    Error err = { 0 };
    Status st = render_util_run(&s, "scalar", 0, &f, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st == ST_OK) {
        float *img = malloc(W * H * 3 * sizeof *img);
        film_resolve(&f, img);
        double on = 0.0;
        for (uint y = H / 2 - 4; y < H / 2 + 4; y++)
            for (uint x = W / 2 - 4; x < W / 2 + 4; x++) on += img[3 * (y * W + x) + 1] / 64.0;
        float corner = img[1];
        fprintf(stderr, "  furnace, albedo %g in a map of 0.8: sphere %.4f (expected %.4f), background %.6f\n",
                (double)albedo, on, 0.8 * albedo, (double)corner);
        CHECK_NEAR(on, 0.8 * albedo, 0.01 * albedo);
        CHECK_NEAR(corner, 0.8, 1e-6);
        free(img);
    }
    film_free(&f);
    scene_free(&s);
    error_clear(&err);
}

static void test_furnace_albedo_1(void) { check_furnace(1.0f); }
static void test_furnace_albedo_half(void) { check_furnace(0.5f); }

/* A diffuse sphere on a diffuse floor under the structured map, direct light only:
 * light sampling alone (the map's own distribution), BSDF sampling alone and their MIS
 * combination (light samples from the compensated distribution) must agree (means of
 * 8x8 blocks and of the image). With the bright sun the compensated distribution is
 * the sun alone; with a dim one about half the map. */
static void check_strategies_agree(float sun)
{
    enum { MW = 48, MH = 24 };
    float *map = structured_map(MW, MH);
    for (uint i = 0; i < MW * MH * 3u; i++)
        if (map[i] == 40.0f) map[i] = sun;
    Scene s;
    sphere_scene(&s, map, MW, MH, 0.7f, 1024, 1);
    uint fm;
    scene_add_material(&s, "floor", material_diffuse(v3(0.6f, 0.5f, 0.4f)), &fm, NULL);
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = v3(0.0f, 1.0f, 0.0f);
    pl.offset = -1.0f;
    pl.material = fm;
    scene_add_plane(&s, pl, NULL);
    float *img[3];
    double mean[3] = { 0.0, 0.0, 0.0 }, block[3][12];
    memset(block, 0, sizeof block);
    Error err = { 0 };
    for (uint m = 0; m < 3; m++) {
        img[m] = malloc(W * H * 3 * sizeof *img[m]);
        Status st = render_util_rgb_mis(&s, m, "scalar", img[m], &err);
        CHECK_MSG(st == ST_OK, "%s", err.msg);
        for (uint y = 0; y < H; y++)
            for (uint x = 0; x < W; x++) {
                const float *p = img[m] + 3 * (y * W + x);
                double val = (p[0] + p[1] + p[2]) / 3.0;
                mean[m] += val / (W * H);
                block[m][(y / 8) * (W / 8) + x / 8] += val / 64.0;
            }
    }
    double worst[3] = { 0.0, 0.0, 0.0 };
    for (uint m = 1; m < 3; m++)
        for (int b = 0; b < 12; b++) {
            double rel = fabs(block[m][b] - block[0][b]) / (block[0][b] > 0.05 ? block[0][b] : 0.05);
            if (rel > worst[m]) worst[m] = rel;
        }
    fprintf(stderr, "  sun %g: image mean: MIS %.4f, light sampling %.4f, BSDF sampling %.4f; worst 8x8 block "
            "difference to MIS: light %.1f%%, BSDF %.1f%%\n", (double)sun, mean[0], mean[1], mean[2], 100.0 * worst[1],
            100.0 * worst[2]);
    CHECK(mean[0] > 0.1);
    CHECK_NEAR(mean[1], mean[0], 0.01 * mean[0]);
    CHECK_NEAR(mean[2], mean[0], 0.01 * mean[0]);
    CHECK(worst[1] < 0.05);
    CHECK(worst[2] < 0.05);
    for (int m = 0; m < 3; m++) free(img[m]);
    scene_free(&s);
    free(map);
    error_clear(&err);
}

static void test_strategies_agree_bright_sun(void) { check_strategies_agree(40.0f); }
static void test_strategies_agree_dim_sun(void) { check_strategies_agree(2.0f); }

/* The same small render with a map (diffuse, metal and glass, every path kind) on PoCL
 * and on the scalar device: the same bits. */
static void test_opencl_matches_scalar(void)
{
    enum { MW = 48, MH = 24 };
    float *map = structured_map(MW, MH);
    Scene s;
    sphere_scene(&s, map, MW, MH, 0.7f, 8, 6);
    uint metal, glass;
    scene_add_material(&s, "metal", material_metal(v3(0.9f, 0.8f, 0.7f), 0.3f), &metal, NULL);
    scene_add_material(&s, "glass", material_dielectric(1.5f), &glass, NULL);
    Sphere a = { v3(-1.2f, -0.5f, 1.0f), 0.5f, metal, NO_INDEX, 0, 0 };
    Sphere b = { v3(1.2f, -0.5f, 1.0f), 0.5f, glass, NO_INDEX, 0, 0 };
    scene_add_sphere(&s, a, NULL);
    scene_add_sphere(&s, b, NULL);
    s.bg_rotate = 20.0f;
    float *img[2];
    const char *devs[2] = { "scalar", TEST_OPENCL };
    Error err = { 0 };
    for (int d = 0; d < 2; d++) {
        img[d] = malloc(W * H * 3 * sizeof *img[d]);
        Status st = render_util_rgb_mis(&s, MIS_BOTH, devs[d], img[d], &err);
        CHECK_MSG(st == ST_OK, "%s: %s", devs[d], err.msg);
    }
    uint same = 0;
    for (uint i = 0; i < W * H; i++) same += memcmp(img[0] + 3 * i, img[1] + 3 * i, 3 * sizeof(float)) == 0;
    fprintf(stderr, "  a map-lit render: %u of %u pixels bit-identical on OpenCL and scalar\n", same, (uint)(W * H));
    CHECK_EQ_INT(same, W * H);
    free(img[0]);
    free(img[1]);
    scene_free(&s);
    free(map);
    error_clear(&err);
}

/* The whitted integrator's camera rays that escape see the map's pixels: an empty
 * scene's image at pixel centres is env_radiance along each camera ray, on PoCL too. */
static void test_whitted_sees_map(void)
{
    enum { MW = 16, MH = 8 };
    float *map = structured_map(MW, MH);
    Scene s;
    sphere_scene(&s, map, MW, MH, 0.5f, 1, 1);
    s.n_spheres = 0;
    s.integrator = INTEGRATOR_WHITTED;
    s.bg_rotate = -30.0f;
    RenderScene rs;
    Error err = { 0 };
    CHECK(render_scene_prepare(&s, 1, &rs, &err) == ST_OK);
    SceneView v;
    device_scene_view(&rs.ds, &v);
    const Camera *c = &rs.ds.params.camera;
    float *want = malloc(W * H * 3 * sizeof *want), *got = malloc(W * H * 3 * sizeof *got);
    for (uint y = 0; y < H; y++)
        for (uint x = 0; x < W; x++) {
            float sx = ((float)x + 0.5f) / W, ty = ((float)y + 0.5f) / H;
            vec3 target = v3_sub(v3_add(c->corner, v3_scale(c->horizontal, sx)), v3_scale(c->vertical, ty));
            vec3 L = env_radiance(&v, v3_sub(target, c->origin));
            memcpy(want + 3 * (y * W + x), &L, sizeof L);
        }
    const char *devs[2] = { "scalar", TEST_OPENCL };
    for (int d = 0; d < 2; d++) {
        CHECK(render_util_rgb_mis(&s, MIS_BOTH, devs[d], got, &err) == ST_OK);
        double worst = 0.0;
        for (uint i = 0; i < W * H * 3; i++) worst = fmax(worst, fabs(got[i] - want[i]));
        fprintf(stderr, "  whitted on %s: largest difference to the map's pixels %.2g\n", devs[d], worst);
        CHECK(worst < 1e-6);
    }
    free(want);
    free(got);
    render_scene_free(&rs);
    scene_free(&s);
    free(map);
    error_clear(&err);
}

/* ------------------------------------------------------------------ files */

/* The shared DWA-compressed maps load, with the size and colours of the Radiance HDR
 * files they were made from (DWA is lossy: means within 2%). */
static void check_shared_exr(const char *exr, const char *hdr)
{
    if (!shared_model_present(exr, "the shared EXR environment maps are not read")) return;
    float *px = NULL;
    int w = 0, h = 0;
    Error err = { 0 };
    Status st = exr_read_rgb(exr, 1u << 26, &px, &w, &h, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    if (st) return;
    CHECK_EQ_INT(w, 1024);
    CHECK_EQ_INT(h, 512);
    double mean[3] = { 0.0, 0.0, 0.0 };
    for (size_t i = 0; i < (size_t)w * h; i++)
        for (int k = 0; k < 3; k++) mean[k] += px[3 * i + k] / ((double)w * h);
    Scene s;
    scene_init(&s);
    uint index;
    CHECK(texture_load_image(&s, NULL, hdr, 1, 0, &index, &err) == ST_OK);
    double ref[3] = { 0.0, 0.0, 0.0 };
    const Texture *t = &s.textures[index];
    CHECK_EQ_INT(t->width, 1024);
    CHECK_EQ_INT(t->height, 512);
    for (size_t i = 0; i < (size_t)w * h; i++)
        for (int k = 0; k < 3; k++) {
            float f;
            memcpy(&f, s.texels + t->offset + 3 * i + k, sizeof f);
            ref[k] += f / ((double)w * h);
        }
    fprintf(stderr, "  %s: %dx%d, mean %.4f %.4f %.4f (the .hdr: %.4f %.4f %.4f)\n", exr, w, h, mean[0], mean[1],
            mean[2], ref[0], ref[1], ref[2]);
    for (int k = 0; k < 3; k++) CHECK_NEAR(mean[k], ref[k], 0.02 * ref[k]);
    free(px);
    scene_free(&s);
    error_clear(&err);
}

static void test_shared_exr_maps_load(void)
{
    check_shared_exr("../shared/envmaps/courtyard-dwab.exr", "../shared/envmaps/courtyard.hdr");
    check_shared_exr("../shared/envmaps/forest-dwab.exr", "../shared/envmaps/forest.hdr");
}

/* The last cell i < n with cdf[i] <= u, by a walk over every cell: what env_cdf_find
 * must return, guide or no guide. */
static uint cell_by_walk(const float *cdf, uint n, float u)
{
    uint i = 0;
    while (i + 1u < n && cdf[i + 1u] <= u) i++;
    return i;
}

/* One cdf of n cells and its guide: env_cdf_find finds the cell a walk finds for u at
 * every cdf value, the floats next to them, the guide's own boundaries k / G and their
 * neighbours, and 0 and the largest float below 1. Returns the number of u tried. */
static uint check_cdf_search(const float *cdf, const float *guide, uint n)
{
    uint g = env_guide_cells(n), tried = 0;
    float us[6];
    for (uint k = 0; k <= n + g; k++) {
        float base = k <= n ? cdf[k] : (float)(k - n - 1u) / (float)g;
        us[0] = base;
        us[1] = nextafterf(base, 0.0f);
        us[2] = nextafterf(base, 1.0f);
        us[3] = 0.0f;
        us[4] = 0.99999994f;
        us[5] = base * 0.5f + 0.25f;
        for (int j = 0; j < 6; j++) {
            float u = us[j], frac;
            if (!(u >= 0.0f && u < 1.0f)) continue;
            uint got = env_cdf_find(cdf, guide, n, u, &frac), want = cell_by_walk(cdf, n, u);
            if (got != want) {
                CHECK_MSG(got == want, "n %u, u %.9g: cell %u, the walk finds %u", n, (double)u, got, want);
                return tried;
            }
            CHECK(frac >= 0.0f && frac < 1.0f);
            tried++;
        }
    }
    return tried;
}

/* The guide tables env_dist_build writes (for both distributions) lead env_cdf_find to
 * the cell a plain walk finds, for maps of 1 to 1024 pixels a row with runs of black pixels (cells of zero
 * probability, where the cdf repeats), single bright pixels and black rows; and the
 * distribution holds exactly the cdfs and guides that kernels/light/envmap.h lays out. */
static void test_guided_search_finds_the_walks_cell(void)
{
    static const uint sizes[][2] = { { 1, 1 }, { 2, 1 }, { 3, 2 }, { 5, 3 }, { 8, 4 }, { 9, 7 }, { 37, 5 },
                                     { 64, 16 }, { 1024, 3 }, { 100, 600 } };
    uint64_t state = 0x9e3779b97f4a7c15u;
    uint tried = 0;
    for (size_t c = 0; c < sizeof sizes / sizeof sizes[0]; c++) {
        uint w = sizes[c][0], h = sizes[c][1];
        float *rgb = malloc((size_t)w * h * 3u * sizeof *rgb);
        for (size_t i = 0; i < (size_t)w * h; i++) {
            state = state * 6364136223846793005u + 1442695040888963407u;
            uint r = (uint)(state >> 33);
            /* half black, a few very bright, whole rows black where the row index is 1 */
            float y = (i / w) == 1u && h > 2u ? 0.0f : (r & 1u) ? 0.0f : (r % 97u == 0u) ? 1e4f : (float)(r % 1000u) / 100.0f;
            rgb[3 * i] = rgb[3 * i + 1] = rgb[3 * i + 2] = y;
        }
        rgb[0] = rgb[1] = rgb[2] = 1.0f; /* never all black */
        uint *bits = malloc((size_t)w * h * 3u * sizeof *bits);
        memcpy(bits, rgb, (size_t)w * h * 3u * sizeof *bits);
        EnvDist dist;
        CHECK(env_dist_build(bits, w, h, &dist, NULL) == ST_OK);
        size_t cdfs = (h + 1u) + (size_t)h * (w + 1u), one = cdfs + env_guide_cells(h) + (size_t)h * env_guide_cells(w);
        CHECK_EQ_INT(env_dist_floats(w, h), one);
        /* two distributions, the compensated one second, unless the map is constant (1 x 1) */
        CHECK_EQ_INT(dist.n, w * h > 1u ? 2u * one : one);
        CHECK_EQ_INT(dist.mis_offset, w * h > 1u ? one : 0u);
        CHECK(dist.cdf != NULL);
        for (size_t at = 0; dist.cdf && at < dist.n; at += one) {
            const float *cdf = dist.cdf + at, *guide = cdf + cdfs;
            tried += check_cdf_search(cdf, guide, h);
            for (uint j = 0; j < h; j++)
                tried += check_cdf_search(cdf + (h + 1u) + j * (w + 1u), guide + env_guide_cells(h) + j * env_guide_cells(w), w);
        }
        free(dist.cdf);
        free(bits);
        free(rgb);
    }
    CHECK(env_guide_cells(1) == 1u && env_guide_cells(7) == 1u && env_guide_cells(8) == 2u &&
          env_guide_cells(1024) == 256u && env_guide_cells(1023) == 128u);
    fprintf(stderr, "  %u searches, each the cell a walk over the cdf finds\n", tried);
}

/* A scene file with a map: parsed, with its defaults and its keys. */
static void test_scene_keys(void)
{
    if (!shared_model_present("../shared/envmaps/courtyard.hdr", "the map scene is not read")) return;
    Scene s;
    scene_init(&s);
    Error err = { 0 };
    const char *text = "background { map \"../shared/envmaps/courtyard-dwab.exr\" intensity 2.5 rotate 45 }\n";
    Status st = scene_load_text("envmap.scene", text, strlen(text), &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    CHECK_EQ_INT(s.bg_type, BG_MAP);
    CHECK(s.bg_color.x == 2.5f && s.bg_rotate == 45.0f);
    /* cdfs, then guides; the map's own distribution and the compensated one */
    CHECK(s.n_env_cdf == 2u * (513u + 512u * 1025u + 128u + 512u * 256u));
    CHECK(s.env_mis_dist == 513u + 512u * 1025u + 128u + 512u * 256u);
    scene_free(&s);
    scene_init(&s);
    text = "background { map \"../shared/envmaps/courtyard.hdr\" }\n";
    CHECK(scene_load_text("envmap.scene", text, strlen(text), &s, &err) == ST_OK);
    CHECK(s.bg_color.x == 1.0f && s.bg_rotate == 0.0f);
    scene_free(&s);
    error_clear(&err);
}

int main(void)
{
    RUN(test_orientation);
    RUN(test_sampling_matches_density);
    RUN(test_sampling_matches_density_rotated);
    RUN(test_compensated_sampling_matches_density);
    RUN(test_compensated_sampling_matches_density_rotated);
    RUN(test_furnace_albedo_1);
    RUN(test_furnace_albedo_half);
    RUN(test_strategies_agree_bright_sun);
    RUN(test_strategies_agree_dim_sun);
    RUN(test_opencl_matches_scalar);
    RUN(test_whitted_sees_map);
    RUN(test_shared_exr_maps_load);
    RUN(test_scene_keys);
    RUN(test_guided_search_finds_the_walks_cell);
    return harness_report();
}
