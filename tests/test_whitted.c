/*
 * test_whitted.c — the classic ray tracer (kernels/integrator/whitted.h) against closed forms:
 * a diffuse plane under a point light has the irradiance of the inverse-square-free
 * (and the attenuated) classic light at every pixel; a Phong highlight peaks where the
 * mirror direction meets the eye; points in shadow get no direct light; spot and
 * directional lights; mirror and refraction rays; the auxiliary images; pixel
 * sampling and the adaptive pass; the same bits on PoCL and the scalar device; BMP and
 * linear 8-bit output.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "render_util.h"

#include "scene/camera.h"
#include "io/classic_parse.h"
#include "io/image_write.h"
#include "render/passes.h"
#include "integrator/whitted.h"

#define KD_R 0.8
#define KD_G 0.6
#define KD_B 0.4

/* A floor (plane y = 0, Phong diffuse colour KD, no specular) seen from (from) looking
 * at the origin, 1 sample per pixel centre, no ambient, black background. */
static void floor_scene(Scene *s, uint w, uint h, vec3 from, vec3 up)
{
    scene_init(s);
    s->image.width = w;
    s->image.height = h;
    s->image.spp = 1;
    s->image.max_depth = 4;
    s->integrator = INTEGRATOR_WHITTED;
    s->camera.from = from;
    s->camera.at = v3(0.0f, 0.0f, 0.0f);
    s->camera.up = up;
    s->camera.vfov = 60.0f;
    uint m;
    scene_add_material(s, "floor", material_phong(v3((float)KD_R, (float)KD_G, (float)KD_B), v3s(0.0f), 0.0f), &m, NULL);
    Plane pl;
    memset(&pl, 0, sizeof pl);
    pl.normal = v3(0.0f, 1.0f, 0.0f);
    pl.material = m;
    scene_add_plane(s, pl, NULL);
}

/* A classic light of colour c (intensity pi c), attenuation a0 a1 a2. */
static void add_point(Scene *s, vec3 pos, float c, float a0, float a1, float a2)
{
    Light l = light_default(LIGHT_POINT);
    l.position = pos;
    l.intensity = v3s(c * (float)M_PI);
    l.atten0 = a0;
    l.atten1 = a1;
    l.atten2 = a2;
    scene_add_light(s, l, NULL);
}

typedef struct { double x, y, z; } D3;

static D3 d3(vec3 v) { D3 r = { v.x, v.y, v.z }; return r; }

/* The camera ray through the centre of pixel (x, y), in double from the float camera. */
static void pixel_ray(const Camera *c, uint w, uint h, uint x, uint y, D3 *o, D3 *d)
{
    double s = (x + 0.5) / w, t = (y + 0.5) / h;
    D3 cr = d3(c->corner), hz = d3(c->horizontal), vt = d3(c->vertical);
    *o = d3(c->origin);
    d->x = cr.x + s * hz.x - t * vt.x - o->x;
    d->y = cr.y + s * hz.y - t * vt.y - o->y;
    d->z = cr.z + s * hz.z - t * vt.z - o->z;
}

static float *render(Scene *s, const char *devices, Film *film)
{
    Error err = {0};
    Status st = render_util_run(s, devices, 0, film, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    size_t n = (size_t)film->width * film->height * 3u;
    float *rgb = calloc(n ? n : 1, sizeof *rgb);
    if (st == ST_OK) film_resolve(film, rgb);
    error_clear(&err);
    return rgb;
}

/* PoCL renders s to the same bits as the scalar device's film `ref`. */
static void check_pocl_matches(Scene *s, const Film *ref)
{
    Film pocl;
    float *rp = render(s, TEST_OPENCL, &pocl);
    size_t n = (size_t)ref->width * ref->height * 3u;
    CHECK(pocl.width == ref->width && pocl.height == ref->height &&
          memcmp(pocl.sum, ref->sum, n * sizeof *pocl.sum) == 0);
    free(rp);
    film_free(&pocl);
}

/* Every floor pixel: kd c cos(theta) / (a0 + a1 d + a2 d^2), within 1e-4. */
static void check_plane_irradiance(float a0, float a1, float a2)
{
    Scene s;
    const uint W = 64, H = 48;
    floor_scene(&s, W, H, v3(0.0f, 3.0f, 4.0f), v3(0.0f, 1.0f, 0.0f));
    vec3 lp = v3(1.0f, 2.5f, 0.5f);
    add_point(&s, lp, 0.9f, a0, a1, a2);
    Camera cam;
    Error err = {0};
    CHECK(camera_setup(&s.camera, W, H, &cam, &err) == ST_OK);
    Film film;
    float *rgb = render(&s, "scalar", &film);
    double worst = 0.0;
    uint checked = 0;
    for (uint y = 0; y < H; y++)
        for (uint x = 0; x < W; x++) {
            D3 o, d;
            pixel_ray(&cam, W, H, x, y, &o, &d);
            if (!(d.y < 0.0)) continue;
            double t = -o.y / d.y;
            D3 p = { o.x + t * d.x, 0.0, o.z + t * d.z };
            D3 l = { lp.x - p.x, lp.y - p.y, lp.z - p.z };
            double dist = sqrt(l.x * l.x + l.y * l.y + l.z * l.z);
            double e = 0.9 * (l.y / dist) / (a0 + a1 * dist + a2 * dist * dist);
            double want[3] = { KD_R * e, KD_G * e, KD_B * e };
            for (int c = 0; c < 3; c++) {
                double err_c = fabs(rgb[3 * (y * W + x) + c] - want[c]);
                if (err_c > worst) worst = err_c;
            }
            checked++;
        }
    fprintf(stderr, "  attenuation %g %g %g: %u floor pixels, worst error %.2g\n", (double)a0, (double)a1,
            (double)a2, checked, worst);
    CHECK(checked > W * H / 3);
    CHECK(worst < 1e-4);
    free(rgb);
    film_free(&film);
    scene_free(&s);
}

static void test_plane_under_point_light(void)
{
    check_plane_irradiance(1.0f, 0.0f, 0.0f);      /* the course's default: no falloff */
    check_plane_irradiance(1.0f, 0.0f, 0.3f);      /* falloff 0.3 */
    check_plane_irradiance(0.5f, 0.2f, 0.1f);      /* attenuation 0.5 0.2 0.1 */
}

/* The same pixels on PoCL and on the scalar device, bit for bit. */
static void test_devices_agree(void)
{
    Scene s;
    floor_scene(&s, 40, 30, v3(0.0f, 3.0f, 4.0f), v3(0.0f, 1.0f, 0.0f));
    add_point(&s, v3(1.0f, 2.5f, 0.5f), 0.9f, 1.0f, 0.0f, 0.0f);
    Sphere sp = { v3(0.0f, 0.6f, 0.0f), 0.6f, 0, NO_INDEX, 0, 0 };
    Material mirror = material_phong(v3s(0.1f), v3s(0.5f), 50.0f);
    mirror.reflective = v3s(0.5f);
    mirror.transparent = v3s(0.4f);
    mirror.ior = 1.5f;
    scene_add_material(&s, "glassy", mirror, &sp.material, NULL);
    scene_add_sphere(&s, sp, NULL);
    s.image.spp = 4;                                   /* a 2x2 jittered grid */
    s.ambient = v3s(0.05f);
    Film a, b;
    float *ra = render(&s, "scalar", &a), *rb = render(&s, TEST_OPENCL, &b);
    size_t n = (size_t)a.width * a.height * 3u;
    CHECK(a.samples == 4 && b.samples == 4);
    CHECK(memcmp(a.sum, b.sum, n * sizeof *a.sum) == 0);
    free(ra);
    free(rb);
    film_free(&a);
    film_free(&b);
    scene_free(&s);
}

/* Projects world point p into film coordinates (s, t) of camera c. */
static void project(const Camera *c, D3 p, double *s, double *t)
{
    /* solve lambda (p - o) = (corner - o) + s h - t v for lambda, s, t (Cramer) */
    D3 o = d3(c->origin), q = { p.x - o.x, p.y - o.y, p.z - o.z };
    D3 k = { c->corner.x - o.x, c->corner.y - o.y, c->corner.z - o.z };
    D3 h = d3(c->horizontal), v = d3(c->vertical);
    /* columns: q, -h, v ; rhs k */
    double m[3][3] = { { q.x, -h.x, v.x }, { q.y, -h.y, v.y }, { q.z, -h.z, v.z } }, rhs[3] = { k.x, k.y, k.z };
    double det = m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                 m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    double x[3];
    for (int col = 0; col < 3; col++) {
        double a[3][3];
        memcpy(a, m, sizeof a);
        for (int r = 0; r < 3; r++) a[r][col] = rhs[r];
        x[col] = (a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                  a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0])) / det;
    }
    *s = x[1];
    *t = x[2];
}

/* A purely specular floor: the brightest pixel is where the mirror image of the eye, the
 * floor point and the light line up. */
static void test_phong_highlight(void)
{
    Scene s;
    const uint W = 160, H = 120;
    floor_scene(&s, W, H, v3(0.0f, 2.0f, 5.0f), v3(0.0f, 1.0f, 0.0f));
    s.materials[0] = material_phong(v3s(0.0f), v3s(1.0f), 400.0f);
    vec3 lp = v3(1.0f, 3.0f, -2.0f);
    add_point(&s, lp, 1.0f, 1.0f, 0.0f, 0.0f);
    Camera cam;
    Error err = {0};
    CHECK(camera_setup(&s.camera, W, H, &cam, &err) == ST_OK);
    Film film;
    float *rgb = render(&s, "scalar", &film);
    uint best = 0;
    for (uint i = 1; i < W * H; i++)
        if (rgb[3 * i] > rgb[3 * best]) best = i;
    /* eye (0 2 5) mirrored: (0 -2 5); the line to the light meets y = 0 at s = 2/5 */
    D3 p = { 0.4 * lp.x, 0.0, 5.0 + 0.4 * (lp.z - 5.0) };
    double fs, ft;
    project(&cam, p, &fs, &ft);
    double px = fs * W - 0.5, py = ft * H - 0.5;
    fprintf(stderr, "  highlight: brightest pixel (%u, %u) = %.4f, mirror point at pixel (%.2f, %.2f)\n", best % W,
            best / W, (double)rgb[3 * best], px, py);
    CHECK(fabs((double)(best % W) - px) <= 1.0 && fabs((double)(best / W) - py) <= 1.0);
    CHECK(rgb[3 * best] > 0.95f && rgb[3 * best] <= 1.0f + 1e-5f);   /* ks c (r.l)^n near 1 */
    free(rgb);
    film_free(&film);
    scene_free(&s);
}

/* Does the segment from p to the light pass through the sphere (with a margin)? */
static int segment_hits_sphere(D3 p, D3 l, D3 c, double r)
{
    D3 d = { l.x - p.x, l.y - p.y, l.z - p.z }, f = { p.x - c.x, p.y - c.y, p.z - c.z };
    double a = d.x * d.x + d.y * d.y + d.z * d.z, b = f.x * d.x + f.y * d.y + f.z * d.z;
    double u = -b / a;
    if (u < 0.0) u = 0.0;
    if (u > 1.0) u = 1.0;
    D3 q = { f.x + u * d.x, f.y + u * d.y, f.z + u * d.z };
    return sqrt(q.x * q.x + q.y * q.y + q.z * q.z) < r;
}

/* A sphere between the light and the floor: shadowed floor points get no direct light
 * at all (exactly the ambient term), the others the closed form. */
static void test_shadow(void)
{
    for (int with_ambient = 0; with_ambient < 2; with_ambient++) {
        Scene s;
        const uint W = 64, H = 64;
        floor_scene(&s, W, H, v3(3.0f, 4.0f, 0.5f), v3(0.0f, 1.0f, 0.0f));
        vec3 lp = v3(0.0f, 3.0f, 0.0f);
        add_point(&s, lp, 1.0f, 1.0f, 0.0f, 0.0f);
        Sphere sp = { v3(0.0f, 1.0f, 0.0f), 0.5f, 0, NO_INDEX, 0, 0 };
        scene_add_sphere(&s, sp, NULL);
        if (with_ambient) s.ambient = v3(0.1f, 0.2f, 0.3f);
        Camera cam;
        Error err = {0};
        CHECK(camera_setup(&s.camera, W, H, &cam, &err) == ST_OK);
        Film film;
        float *rgb = render(&s, TEST_OPENCL, &film);
        uint shadowed = 0, lit = 0, bad = 0;
        D3 c = { 0.0, 1.0, 0.0 }, l = d3(lp);
        for (uint y = 0; y < H; y++)
            for (uint x = 0; x < W; x++) {
                D3 o, d;
                pixel_ray(&cam, W, H, x, y, &o, &d);
                if (!(d.y < 0.0)) continue;
                double t = -o.y / d.y;
                D3 p = { o.x + t * d.x, 0.0, o.z + t * d.z };
                if (segment_hits_sphere(o, p, c, 0.51)) continue;          /* the camera sees the sphere */
                const float *px = rgb + 3 * (y * W + x);
                double amb[3] = { 0.1 * KD_R, 0.2 * KD_G, 0.3 * KD_B };
                if (segment_hits_sphere(p, l, c, 0.49)) {
                    shadowed++;
                    for (int k = 0; k < 3; k++)
                        if (fabs(px[k] - (with_ambient ? amb[k] : 0.0)) > (with_ambient ? 1e-6 : 0.0)) bad++;
                } else if (!segment_hits_sphere(p, l, c, 0.51)) {
                    lit++;
                    D3 v = { l.x - p.x, l.y - p.y, l.z - p.z };
                    double e = (v.y / sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
                    double want[3] = { KD_R * e, KD_G * e, KD_B * e };
                    for (int k = 0; k < 3; k++)
                        if (fabs(px[k] - want[k] - (with_ambient ? amb[k] : 0.0)) > 1e-4) bad++;
                }
            }
        fprintf(stderr, "  shadow%s: %u shadowed floor pixels, %u lit, %u wrong\n", with_ambient ? " (ambient)" : "",
                shadowed, lit, bad);
        CHECK(shadowed > 50 && lit > 1000);
        CHECK_EQ_INT(bad, 0);
        free(rgb);
        film_free(&film);
        scene_free(&s);
    }
}

/* The shadow scene of test_shadow (point light above a sphere over the floor, ambient
 * 0.1 0.2 0.3), shadows on or off, with the integrator given. */
static void shadow_switch_scene(Scene *s, uint integrator, int shadows, int with_sphere)
{
    floor_scene(s, 64, 64, v3(3.0f, 4.0f, 0.5f), v3(0.0f, 1.0f, 0.0f));
    add_point(s, v3(0.0f, 3.0f, 0.0f), 1.0f, 1.0f, 0.0f, 0.0f);
    s->ambient = v3(0.1f, 0.2f, 0.3f);
    s->integrator = integrator;
    s->shadows = shadows;
    if (!with_sphere) return;
    Sphere sp = { v3(0.0f, 1.0f, 0.0f), 0.5f, 0, NO_INDEX, 0, 0 };
    /* black, so that the path tracer's bounce off it brings nothing */
    scene_add_material(s, "black", material_diffuse(v3s(0.0f)), &sp.material, NULL);
    scene_add_sphere(s, sp, NULL);
}

/* --shadows off, whitted: the floor point right under the sphere (in its shadow with
 * shadows on: exactly ambient x kd) gets the full closed-form light, as every floor pixel
 * does; the same bits on PoCL and the scalar device. */
static void test_shadows_off_whitted(void)
{
    const uint W = 64, H = 64;
    D3 c = { 0.0, 1.0, 0.0 }, l = { 0.0, 3.0, 0.0 };
    double amb[3] = { 0.1 * KD_R, 0.2 * KD_G, 0.3 * KD_B };
    float *rgb[2];
    Film film[2];
    Camera cam;
    for (int on = 0; on < 2; on++) {
        Scene s;
        shadow_switch_scene(&s, INTEGRATOR_WHITTED, on, 1);
        Error err = {0};
        CHECK(camera_setup(&s.camera, W, H, &cam, &err) == ST_OK);
        rgb[on] = render(&s, "scalar", &film[on]);
        if (!on) check_pocl_matches(&s, &film[0]);
        scene_free(&s);
    }
    /* the pixel whose floor point is nearest (0, 0, 0), right under the sphere */
    uint best = 0, bad = 0, lit = 0;
    double best_r = INFINITY;
    for (uint y = 0; y < H; y++)
        for (uint x = 0; x < W; x++) {
            D3 o, d;
            pixel_ray(&cam, W, H, x, y, &o, &d);
            if (!(d.y < 0.0)) continue;
            double t = -o.y / d.y;
            D3 p = { o.x + t * d.x, 0.0, o.z + t * d.z };
            if (segment_hits_sphere(o, p, c, 0.51)) continue;
            double r = sqrt(p.x * p.x + p.z * p.z);
            if (r < best_r) best_r = r, best = y * W + x;
            D3 v = { l.x - p.x, l.y - p.y, l.z - p.z };
            double e = v.y / sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
            double want[3] = { KD_R * e + amb[0], KD_G * e + amb[1], KD_B * e + amb[2] };
            for (int k = 0; k < 3; k++)
                if (fabs(rgb[0][3 * (y * W + x) + k] - want[k]) > 1e-4) bad++;
            lit++;
        }
    const float *on_px = rgb[1] + 3 * best, *off_px = rgb[0] + 3 * best;
    fprintf(stderr, "  floor under the sphere (%.2f from its foot): shadows on %.4f %.4f %.4f, off %.4f %.4f %.4f; "
            "%u floor pixels, %u wrong\n", best_r, (double)on_px[0], (double)on_px[1], (double)on_px[2],
            (double)off_px[0], (double)off_px[1], (double)off_px[2], lit, bad);
    CHECK(best_r < 0.3);
    CHECK(lit > 1000);
    CHECK_EQ_INT(bad, 0);
    /* on: ambient alone, exactly; off: ambient + kd (the light straight above, cos 1, d 3
     * with no falloff: irradiance 1) up to the pixel's small offset from the foot */
    for (int k = 0; k < 3; k++) {
        CHECK(fabs(on_px[k] - amb[k]) <= 1e-6);
        double kd = k == 0 ? KD_R : (k == 1 ? KD_G : KD_B);
        CHECK(fabs(off_px[k] - (amb[k] + kd)) < 0.02);
    }
    for (int on = 0; on < 2; on++) {
        free(rgb[on]);
        film_free(&film[on]);
    }
}

/* --shadows off, path tracer: next-event estimation counts the point light as visible.
 * With one bounce (the floor's light sample; what it scatters to is black) a floor
 * pixel deep in the sphere's shadow is exactly 0 with shadows on, and with shadows off
 * the same bits as the scene without the sphere; PoCL and scalar agree. */
static void test_shadows_off_path(void)
{
    const uint W = 64, H = 64;
    Film f[3];
    float *rgb[3];
    Camera cam;
    for (int i = 0; i < 3; i++) {            /* 0: off, 1: on, 2: off without the sphere */
        Scene s;
        shadow_switch_scene(&s, INTEGRATOR_PATH, i == 1, i != 2);
        s.image.max_depth = 1;
        Error err = {0};
        CHECK(camera_setup(&s.camera, W, H, &cam, &err) == ST_OK);
        rgb[i] = render(&s, "scalar", &f[i]);
        if (i == 0) check_pocl_matches(&s, &f[0]);
        scene_free(&s);
    }
    D3 c = { 0.0, 1.0, 0.0 }, l = { 0.0, 3.0, 0.0 };
    uint deep = 0, same = 0, checked = 0, dark = 0;
    float one_on = -1.0f, one_off = -1.0f;
    for (uint y = 0; y < H; y++)
        for (uint x = 0; x < W; x++) {
            D3 o, d;
            pixel_ray(&cam, W, H, x, y, &o, &d);
            if (!(d.y < 0.0)) continue;
            double t = -o.y / d.y;
            D3 p = { o.x + t * d.x, 0.0, o.z + t * d.z };
            if (segment_hits_sphere(o, p, c, 0.6)) continue;   /* near the sphere's outline */
            size_t k = 3 * ((size_t)y * W + x);
            checked++;
            if (memcmp(&rgb[0][k], &rgb[2][k], 3 * sizeof(float)) == 0) same++;
            if (!segment_hits_sphere(p, l, c, 0.35)) continue;   /* the whole pixel in shadow */
            deep++;
            if (rgb[1][k] == 0.0f && rgb[1][k + 1] == 0.0f && rgb[1][k + 2] == 0.0f) dark++;
            one_on = rgb[1][k];
            one_off = rgb[0][k];
        }
    fprintf(stderr, "  path: %u of %u floor pixels with shadows off are the bits of the scene without the "
            "sphere; %u of %u deep in its shadow black with shadows on (one: red %.4f on, %.4f off)\n",
            same, checked, dark, deep, (double)one_on, (double)one_off);
    CHECK(checked > 1000 && same == checked);
    CHECK(deep > 20 && dark == deep);
    CHECK(one_off > 0.5f);
    for (int i = 0; i < 3; i++) {
        free(rgb[i]);
        film_free(&f[i]);
    }
}

/* A directional light lights the floor evenly; a spot light fully inside its inner cone,
 * not at all outside its outer one, in between by a smooth step. */
static void test_directional_and_spot(void)
{
    Scene s;
    const uint W = 48, H = 48;
    floor_scene(&s, W, H, v3(0.0f, 6.0f, 0.01f), v3(0.0f, 0.0f, -1.0f));
    Light dl = light_default(LIGHT_DIRECTIONAL);
    dl.direction = v3_norm(v3(1.0f, -2.0f, 0.0f));
    dl.intensity = v3s(0.5f * (float)M_PI);
    scene_add_light(&s, dl, NULL);
    Film film;
    float *rgb = render(&s, "scalar", &film);
    double cos_t = 2.0 / sqrt(5.0), worst = 0.0;
    for (uint i = 0; i < W * H; i++) {
        double e = fabs(rgb[3 * i] - KD_R * 0.5 * cos_t);
        if (e > worst) worst = e;
    }
    CHECK(worst < 1e-5);
    free(rgb);
    film_free(&film);
    /* the spot straight down from (0 2 0): inner 20, outer 40 degrees */
    s.n_delta_lights = 0;
    Light sl = light_default(LIGHT_SPOT);
    sl.position = v3(0.0f, 2.0f, 0.0f);
    sl.direction = v3(0.0f, -1.0f, 0.0f);
    sl.intensity = v3s((float)M_PI);
    sl.atten0 = 1.0f;
    sl.atten2 = 0.0f;
    sl.cos_inner = (float)cos(20.0 * M_PI / 180.0);
    sl.cos_outer = (float)cos(40.0 * M_PI / 180.0);
    scene_add_light(&s, sl, NULL);
    Camera cam;
    Error err = {0};
    CHECK(camera_setup(&s.camera, W, H, &cam, &err) == ST_OK);
    rgb = render(&s, "scalar", &film);
    uint inner = 0, outer = 0, between = 0, bad = 0;
    for (uint y = 0; y < H; y++)
        for (uint x = 0; x < W; x++) {
            D3 o, d;
            pixel_ray(&cam, W, H, x, y, &o, &d);
            double t = -o.y / d.y;
            D3 p = { o.x + t * d.x, 0.0, o.z + t * d.z };
            double r = sqrt(p.x * p.x + p.z * p.z), dist = sqrt(r * r + 4.0), c = 2.0 / dist;
            float v = rgb[3 * (y * W + x)];
            if (c > cos(19.0 * M_PI / 180.0)) {
                inner++;
                bad += fabs(v - KD_R * c) > 1e-4;
            } else if (c < cos(41.0 * M_PI / 180.0)) {
                outer++;
                bad += v != 0.0f;
            } else if (c < cos(21.0 * M_PI / 180.0) && c > cos(39.0 * M_PI / 180.0)) {
                between++;
                bad += !(v > 0.0f && v < KD_R * c);
            }
        }
    fprintf(stderr, "  spot: %u pixels inside, %u outside, %u on the edge, %u wrong\n", inner, outer, between, bad);
    CHECK(inner > 20 && outer > 200 && between > 50);
    CHECK_EQ_INT(bad, 0);
    free(rgb);
    film_free(&film);
    scene_free(&s);
}

/* A tinted mirror sphere in a constant background: the sphere's pixels are exactly the
 * background times the tint (the mirror ray carries it whole), the rest the background;
 * a clear glass sphere returns the background too, to within what the depth limit and
 * the weight cut-off drop. */
static void test_mirror_and_glass(void)
{
    for (int glass = 0; glass < 2; glass++) {
        Scene s;
        scene_init(&s);
        s.image.width = 48;
        s.image.height = 48;
        s.image.spp = 1;
        s.image.max_depth = 24;
        s.integrator = INTEGRATOR_WHITTED;
        s.camera.from = v3(0.0f, 0.0f, 4.0f);
        s.camera.vfov = 40.0f;
        s.bg_color = s.bg_zenith = v3(0.5f, 0.25f, 1.0f);
        Material m = material_phong(v3s(0.0f), v3s(0.0f), 0.0f);
        if (glass) {
            m.transparent = v3s(1.0f);
            m.ior = 1.5f;
        } else {
            m.reflective = v3(1.0f, 0.5f, 0.25f);
        }
        Sphere sp = { v3(0.0f, 0.0f, 0.0f), 1.0f, 0, NO_INDEX, 0, 0 };
        scene_add_material(&s, "m", m, &sp.material, NULL);
        scene_add_sphere(&s, sp, NULL);
        Film film;
        float *rgb = render(&s, "scalar", &film);
        uint tinted = 0, plain = 0, other = 0;
        double worst = 0.0;
        for (uint i = 0; i < 48 * 48; i++) {
            const float *p = rgb + 3 * i;
            if (p[0] == 0.5f && p[1] == 0.25f && p[2] == 1.0f) plain++;
            else if (!glass && p[0] == 0.5f && p[1] == 0.125f && p[2] == 0.25f) tinted++;
            else other++;
            double e = fabs(p[0] - 0.5) + fabs(p[1] - 0.25) + fabs(p[2] - 1.0);
            if (e > worst) worst = e;
        }
        if (glass) {
            fprintf(stderr, "  glass sphere: worst deviation from the background %.2g\n", worst);
            CHECK(worst < 2e-3);
            CHECK(other > 500);                   /* it does go through the sphere */
        } else {
            CHECK(tinted > 500 && plain > 500);
            CHECK_EQ_INT(other, 0);
        }
        free(rgb);
        film_free(&film);
        scene_free(&s);
    }
}

/* Snell's law, total internal reflection, Fresnel at normal incidence. */
static void test_refraction(void)
{
    vec3 n = v3(0.0f, 1.0f, 0.0f), t;
    float si = 0.5f;
    vec3 d = v3(si, -sqrtf(1.0f - si * si), 0.0f);
    CHECK(refract_dir(d, n, 1.5f, &t));
    CHECK_NEAR(t.x * 1.5, si, 1e-6);                      /* n1 sin(i) = n2 sin(t) */
    CHECK(t.y < 0.0f);
    CHECK_NEAR(v3_len(t), 1.0, 1e-6);
    si = 0.8f;                                             /* from glass: 1.5 * 0.8 > 1 */
    d = v3(si, -sqrtf(1.0f - si * si), 0.0f);
    CHECK(!refract_dir(d, n, 1.0f / 1.5f, &t));
    CHECK_NEAR(fresnel_dielectric(1.0f, 1.5f), 0.04, 1e-6);
    CHECK(fresnel_dielectric(0.6f, 1.0f / 1.5f) == 1.0f);
}

/* The auxiliary images of the floor: its normal, its distance, its colour. */
static void test_aovs(void)
{
    const uint W = 32, H = 24;
    uint modes[] = { INTEGRATOR_AOV_NORMAL, INTEGRATOR_AOV_DEPTH, INTEGRATOR_AOV_ALBEDO };
    for (int m = 0; m < 3; m++) {
        Scene s;
        floor_scene(&s, W, H, v3(0.0f, 3.0f, 4.0f), v3(0.0f, 1.0f, 0.0f));
        s.integrator = modes[m];
        Camera cam;
        Error err = {0};
        CHECK(camera_setup(&s.camera, W, H, &cam, &err) == ST_OK);
        Film film;
        float *rgb = render(&s, "scalar", &film);
        uint bad = 0, floor = 0;
        for (uint y = 0; y < H; y++)
            for (uint x = 0; x < W; x++) {
                D3 o, d;
                pixel_ray(&cam, W, H, x, y, &o, &d);
                const float *p = rgb + 3 * (y * W + x);
                if (!(d.y < 0.0)) {
                    bad += !(p[0] == 0.0f && p[1] == 0.0f && p[2] == 0.0f);
                    continue;
                }
                floor++;
                double t = -o.y / d.y, len = sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
                if (modes[m] == INTEGRATOR_AOV_NORMAL) bad += !(p[0] == 0.5f && p[1] == 1.0f && p[2] == 0.5f);
                if (modes[m] == INTEGRATOR_AOV_DEPTH) bad += fabs(p[0] - t * len) > 1e-4 * t * len || p[1] != 1.0f;
                if (modes[m] == INTEGRATOR_AOV_ALBEDO)
                    bad += fabs(p[0] - KD_R) > 1e-7 || fabs(p[1] - KD_G) > 1e-7 || fabs(p[2] - KD_B) > 1e-7;
            }
        CHECK(floor > W * H / 3);
        CHECK_MSG(bad == 0, "aov %u: %u pixels wrong", modes[m], bad);
        free(rgb);
        film_free(&film);
        scene_free(&s);
    }
}

/* One ray through the pixel centre; an m x m grid puts one sample in each cell. */
static void test_pixel_sampling(void)
{
    RenderParams p;
    memset(&p, 0, sizeof p);
    p.width = 10;
    p.height = 10;
    p.seed = 3;
    p.camera.type = CAMERA_ORTHOGRAPHIC;       /* the ray's origin is the film point */
    p.camera.horizontal = v3(10.0f, 0.0f, 0.0f);
    p.camera.vertical = v3(0.0f, 10.0f, 0.0f);
    p.camera.forward = v3(0.0f, 0.0f, -1.0f);
    RngKey key;
    float wtime;
    Ray r = whitted_camera_ray(&p, NULL, 34, 0, &key, &wtime);   /* pixel (4, 3) */
    CHECK(r.o.x == 4.5f && r.o.y == -3.5f);
    r = whitted_camera_ray(&p, NULL, 34, 7, &key, &wtime);
    CHECK(r.o.x == 4.5f && r.o.y == -3.5f);        /* every sample, without jitter */
    p.strata = 2;
    int cells[4] = { 0, 0, 0, 0 };
    for (uint sm = 0; sm < 4; sm++) {
        r = whitted_camera_ray(&p, NULL, 34, sm, &key, &wtime);
        float fx = r.o.x - 4.0f, fy = -r.o.y - 3.0f;
        CHECK(fx > 0.0f && fx < 1.0f && fy > 0.0f && fy < 1.0f);
        cells[(fx >= 0.5f) + 2 * (fy >= 0.5f)]++;
    }
    CHECK(cells[0] == 1 && cells[1] == 1 && cells[2] == 1 && cells[3] == 1);
    CHECK_EQ_INT(render_scene_strata(1), 0);
    CHECK_EQ_INT(render_scene_strata(16), 4);
    CHECK_EQ_INT(render_scene_strata(10), 1);
    CHECK_EQ_INT(render_scene_strata(1000000), 1000);
}

/* The adaptive pass: only pixels next to a strong difference get more samples, and an
 * edge pixel ends up between the colours on either side. */
static void test_adaptive(void)
{
    float img[5 * 3 * 3];
    for (int i = 0; i < 15; i++) {
        float v = (i % 5) >= 3 ? 1.0f : 0.0f;
        img[3 * i] = img[3 * i + 1] = img[3 * i + 2] = v;
    }
    img[3 * 7] = 0.05f;                                   /* a small difference: no mark */
    uint mask[15];
    CHECK_EQ_INT(passes_mark_edges(img, 5, 3, 0.1f, mask), 6);
    for (int i = 0; i < 15; i++) CHECK_EQ_INT(mask[i], (i % 5 == 2 || i % 5 == 3) ? 1u : 0u);

    /* end to end: a red sphere on black */
    Scene s;
    scene_init(&s);
    s.image.width = 40;
    s.image.height = 40;
    s.image.spp = 1;
    s.integrator = INTEGRATOR_WHITTED;
    s.camera.from = v3(0.0f, 0.0f, 4.0f);
    s.camera.vfov = 40.0f;
    s.ambient = v3s(1.0f);
    Sphere sp = { v3(0.0f, 0.0f, 0.0f), 1.0f, 0, NO_INDEX, 0, 0 };
    scene_add_material(&s, "red", material_phong(v3(1.0f, 0.0f, 0.0f), v3s(0.0f), 0.0f), &sp.material, NULL);
    scene_add_sphere(&s, sp, NULL);
    RenderScene rs;
    Error err = {0};
    CHECK(render_scene_prepare(&s, 1, &rs, &err) == ST_OK);
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0;
    char warning[1100];
    CHECK(device_list(&all, &n_all, warning, sizeof warning, &err) == ST_OK);
    char spec[32];
    snprintf(spec, sizeof spec, "scalar,%s", TEST_OPENCL);
    CHECK(device_select(spec, all, n_all, &chosen, &n_chosen, &err) == ST_OK);
    Device *devs[4];
    size_t n_dev = 0;
    for (size_t i = 0; i < n_chosen && n_dev < 4; i++)
        if (device_open(&all[chosen[i]], NULL, &devs[n_dev], &err) == ST_OK) n_dev++;
    CHECK(n_dev == 2);
    for (size_t i = 0; i < n_dev; i++) CHECK(devs[i]->ops->load_scene(devs[i], &rs.ds, &err) == ST_OK);
    Film film;
    film_init(&film, 40, 40, &err);
    ScheduleConfig cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.spp = 1;
    ScheduleStats stats;
    CHECK(schedule_run(devs, n_dev, &cfg, &film, &stats, &err) == ST_OK);
    schedule_stats_free(&stats);
    float *base = malloc(40 * 40 * 3 * sizeof *base), *rgb = malloc(40 * 40 * 3 * sizeof *rgb);
    film_resolve(&film, base);
    memcpy(rgb, base, 40 * 40 * 3 * sizeof *rgb);
    PassContext pc = { .devices = devs, .n_devices = n_dev, .rs = &rs, .cfg = &cfg };
    size_t marked = 0;
    double secs = 0.0;
    CHECK(passes_adaptive(&pc, rgb, 1, 0.25f, 16, &marked, &secs, &err) == ST_OK);
    uint changed = 0, between = 0, changed_unmarked = 0;
    uint mask2[1600];
    passes_mark_edges(base, 40, 40, 0.25f, mask2);
    for (uint i = 0; i < 1600; i++) {
        int diff = rgb[3 * i] != base[3 * i];
        changed += diff;
        if (diff && !mask2[i]) changed_unmarked++;
        between += mask2[i] && rgb[3 * i] > 0.02f && rgb[3 * i] < 0.98f;
    }
    fprintf(stderr, "  adaptive: %zu of 1600 pixels marked, %u changed, %u now between the two colours\n", marked,
            changed, between);
    CHECK(marked > 40 && marked < 400);                   /* the silhouette, not the image */
    CHECK_EQ_INT(changed_unmarked, 0);
    CHECK(between > 20);
    CHECK(rs.ds.params.pixel_list_size == 0 && rs.ds.pixel_list == NULL);   /* restored */
    for (size_t i = 0; i < n_dev; i++) device_close(devs[i]);
    free(all);
    free(chosen);
    free(base);
    free(rgb);
    film_free(&film);
    render_scene_free(&rs);
    scene_free(&s);
    error_clear(&err);
}

/* ------------------------------------------------------------ the course conventions */

/* A classic scene from text, w x h, one ray per pixel centre, rendered on `devices`
 * (or, with "both", on the scalar device and PoCL, which must agree bit for bit). */
static float *render_classic(const char *text, uint w, uint h, uint integrator, const char *devices)
{
    Scene s;
    scene_init(&s);
    Error err = {0};
    Status st = classic_load_text("conv.txt", text, strlen(text), &s, &err);
    CHECK_MSG(st == ST_OK, "%s", err.msg);
    error_clear(&err);
    s.image.width = w;
    s.image.height = h;
    s.image.max_depth = 4;
    if (integrator != INTEGRATOR_WHITTED) s.integrator = integrator;
    int both = strcmp(devices, "both") == 0;
    Film film;
    float *rgb = render(&s, both ? "scalar" : devices, &film);
    if (both) {
        Film other;
        float *again = render(&s, TEST_OPENCL, &other);
        CHECK(memcmp(film.sum, other.sum, (size_t)w * h * 3u * sizeof *film.sum) == 0);
        free(again);
        film_free(&other);
    }
    film_free(&film);
    scene_free(&s);
    return rgb;
}

/* MIT 6.837 Fall 2019's point light: color / (falloff d^2). A floor of diffuse colour
 * (0.8, 0.6, 0.4) 2 under a light with falloff 0.5, seen straight down at its foot:
 * 0.8 / (0.5 x 4) = 0.4 (before: color / (1 + falloff d^2) gave 0.8 / 3 = 0.267). */
static void test_course_falloff(void)
{
    const char *scene =
        "PerspectiveCamera { center 0 5 0 direction 0 -1 0 up 0 0 -1 angle 30 }\n"
        "Lights { numLights 1 PointLight { position 0 2 0 color 1 1 1 falloff 0.5 } }\n"
        "Background { color 0 0 0 ambientLight 0 0 0 }\n"
        "Materials { numMaterials 1 Material { diffuseColor 0.8 0.6 0.4 } }\n"
        "Group { numObjects 1 MaterialIndex 0 Plane { normal 0 1 0 offset 0 } }\n";
    float *rgb = render_classic(scene, 3, 3, INTEGRATOR_WHITTED, "both");
    const float *c = rgb + 3 * 4;
    fprintf(stderr, "  falloff 0.5 at d = 2: centre pixel %.4f %.4f %.4f (course 0.4 0.3 0.2)\n", (double)c[0],
            (double)c[1], (double)c[2]);
    CHECK_NEAR(c[0], 0.4, 1e-6);
    CHECK_NEAR(c[1], 0.3, 1e-6);
    CHECK_NEAR(c[2], 0.2, 1e-6);
    free(rgb);
}

/* The course's camera spans the image with normalize(direction x up) and `up` as given:
 * looking down 45 degrees with up 0 1 0, the vertical edge x = 1 of a triangle stays in
 * one column, the one the course's projection puts it in: the point's horizontal film
 * coordinate is d / (5 sqrt 2) with d = 1 / tan(30 deg), column floor((1 + sx) / 2 x 64)
 * + 1 = 40 for every row it crosses (the orthonormal frame clpt used before slanted it
 * over columns 38..43). */
static void test_course_camera(void)
{
    const uint W = 64, H = 64;
    const char *scene =
        "PerspectiveCamera { center 0 5 5 direction 0 -1 -1 up 0 1 0 angle 60 }\n"
        "Background { color 0 0 0 ambientLight 1 1 1 }\n"
        "Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n"
        "Group { numObjects 1 MaterialIndex 0 Triangle { vertex0 1 -3 0 vertex1 6 0 0 vertex2 1 3 0 } }\n";
    float *rgb = render_classic(scene, W, H, INTEGRATOR_WHITTED, "both");
    uint rows = 0, lo = W, hi = 0;
    for (uint y = 0; y < H; y++) {
        uint x = 0;
        while (x < W && rgb[3 * (y * W + x)] == 0.0f) x++;
        if (x == W) continue;
        rows++;
        if (x < lo) lo = x;
        if (x > hi) hi = x;
    }
    fprintf(stderr, "  camera looking down: the vertical edge in columns %u..%u over %u rows\n", lo, hi, rows);
    CHECK(rows > 10);
    CHECK_EQ_INT(lo, 40);
    CHECK_EQ_INT(hi, 40);
    free(rgb);
}

/* Fall 2019: a material with specularColor mirrors with it, `Material` and
 * `PhongMaterial` alike (the course's scene07_arch floor is a PhongMaterial of
 * specularColor 0.4). A black sphere with specular 0.5 in front of a (0.2, 0.4, 0.8)
 * background reflects the background straight back at the centre pixel: 0.5 x
 * background (before: black, and black for PhongMaterial until the arch's floor
 * showed it). Tsinghua's dialect (a camera with width/height) reflects nothing, nor
 * does a scene in MIT 2004's dialect (a material with reflectiveColor, transparentColor,
 * indexOfRefraction or exponent), where only reflectiveColor mirrors. */
static void test_course_reflection(void)
{
    const char *cameras[2] = { "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }\n",
                               "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 "
                               "width 3 height 3 }\n" };
    const char *blocks[3] = { "Material", "PhongMaterial", "PhongMaterial" };
    const char *others[3] = { "", "", "PhongMaterial { diffuseColor 1 1 1 transparentColor 0.5 0.5 0.5 }" };
    for (int sized = 0; sized < 2; sized++)
        for (int b = 0; b < 3; b++) {
            char scene[1024];
            snprintf(scene, sizeof scene,
                     "%sBackground { color 0.2 0.4 0.8 ambientLight 0 0 0 }\n"
                     "Materials { numMaterials %d %s { diffuseColor 0 0 0 specularColor 0.5 0.5 0.5 shininess 10 } "
                     "%s }\n"
                     "Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n",
                     cameras[sized], others[b][0] ? 2 : 1, blocks[b], others[b]);
            float *rgb = render_classic(scene, 3, 3, INTEGRATOR_WHITTED, "both");
            const float *c = rgb + 3 * 4;
            fprintf(stderr, "  specular 0.5 sphere (%s%s), %s camera: centre pixel %.4f %.4f %.4f\n", blocks[b],
                    b == 2 ? ", 2004 keys" : "", sized ? "Tsinghua" : "MIT", (double)c[0], (double)c[1], (double)c[2]);
            double k = sized || b == 2 ? 0.0 : 0.5;
            CHECK_NEAR(c[0], 0.2 * k, 1e-6);
            CHECK_NEAR(c[1], 0.4 * k, 1e-6);
            CHECK_NEAR(c[2], 0.8 * k, 1e-6);
            free(rgb);
        }
}

/* Fall 2019's meshes without `vn` get smooth normals: a two-triangle tent whose faces
 * have normals (-1, 0, 1) / sqrt 2 and (1, 0, 1) / sqrt 2 shares its ridge B C, whose
 * vertex normal is then +z. The orthographic pixel (3, 3) of 8 x 8 over 4 units sees
 * x = -0.25 on the left face, barycentric 0.25 for the apex A: its normal is
 * normalize(0.25 nA + 0.75 z) = (-0.18737, 0, 0.98229) (flat before: (-0.70711, 0,
 * 0.70711)), and still flat with a sized camera (Tsinghua). */
static void test_course_mesh_normals(void)
{
    char dirname[] = "/tmp/clpt-conv-XXXXXX";
    CHECK(mkdtemp(dirname) != NULL);
    char obj[64];
    snprintf(obj, sizeof obj, "%s/tent.obj", dirname);
    FILE *f = fopen(obj, "w");
    CHECK(f != NULL);
    if (!f) return;
    fputs("v -1 0 0\nv 0 -1 1\nv 0 1 1\nv 1 0 0\nf 1 2 3\nf 2 4 3\n", f);
    fclose(f);
    double a = 0.25 * sqrt(0.5), len = sqrt(a * a + (a + 0.75) * (a + 0.75));
    double smooth[3] = { (-a / len + 1) / 2, 0.5, ((a + 0.75) / len + 1) / 2 };
    double flat[3] = { (-sqrt(0.5) + 1) / 2, 0.5, (sqrt(0.5) + 1) / 2 };
    for (int sized = 0; sized < 2; sized++) {
        char scene[512];
        snprintf(scene, sizeof scene,
                 "OrthographicCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 size 4 %s}\n"
                 "Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n"
                 "Group { numObjects 1 MaterialIndex 0 TriangleMesh { obj_file %s } }\n",
                 sized ? "width 8 height 8 " : "", obj);
        float *rgb = render_classic(scene, 8, 8, INTEGRATOR_AOV_NORMAL, "both");
        const float *p = rgb + 3 * (3 * 8 + 3);
        const double *want = sized ? flat : smooth;
        fprintf(stderr, "  tent mesh, %s camera: normal image at (3, 3) %.5f %.5f %.5f\n", sized ? "Tsinghua" : "MIT",
                (double)p[0], (double)p[1], (double)p[2]);
        for (int c = 0; c < 3; c++) CHECK_NEAR(p[c], want[c], 1e-5);
        free(rgb);
    }
    remove(obj);
    rmdir(dirname);
}

/* The normal image of a classic scene writes (0 + 1) / 2 where the ray escapes; the
 * depth image's --depth-range NEAR > FAR ramps black at the near distance to white at
 * the far one, misses black. */
static void test_course_aovs(void)
{
    const char *scene =
        "PerspectiveCamera { center 0 0 10 direction 0 0 -1 up 0 1 0 angle 30 }\n"
        "Materials { numMaterials 1 Material { diffuseColor 1 1 1 } }\n"
        "Group { numObjects 1 MaterialIndex 0 Sphere { center 0 0 0 radius 1 } }\n";
    float *rgb = render_classic(scene, 5, 5, INTEGRATOR_AOV_NORMAL, "both");
    fprintf(stderr, "  normal image: corner (miss) %.2f %.2f %.2f, centre %.2f %.2f %.2f\n", (double)rgb[0],
            (double)rgb[1], (double)rgb[2], (double)rgb[36], (double)rgb[37], (double)rgb[38]);
    CHECK(rgb[0] == 0.5f && rgb[1] == 0.5f && rgb[2] == 0.5f);
    CHECK_NEAR(rgb[36], 0.5, 1e-6);
    CHECK_NEAR(rgb[37], 0.5, 1e-6);
    CHECK_NEAR(rgb[38], 1.0, 1e-6);    /* n = +z at the centre */
    free(rgb);

    /* distances 8, 10.5, 13, 18 and 20 (resolved as distance x coverage, coverage), a miss */
    float depth[] = { 8, 1, 0, 10.5f, 1, 0, 13, 1, 0, 18, 1, 0, 20, 1, 0, 0, 0, 0 };
    DepthScale course = { DEPTH_RANGE, 18.0, 8.0 };
    passes_depth_grey(depth, 6, &course);
    const float want[] = { 0.0f, 0.25f, 0.5f, 1.0f, 1.0f, 0.0f };
    for (int i = 0; i < 6; i++) CHECK_NEAR(depth[3 * i], want[i], 1e-6);
    float again[] = { 8, 1, 0, 13, 1, 0 };
    DepthScale clpt = { DEPTH_RANGE, 8.0, 18.0 };
    passes_depth_grey(again, 2, &clpt);
    CHECK(again[0] == 1.0f);
    CHECK_NEAR(again[3], 0.5, 1e-6);
}

/* BMP: header, bottom-up BGR rows padded to 4 bytes; linear or sRGB bytes. */
static void test_bmp(void)
{
    char path[] = "/tmp/clpt-test-bmp-XXXXXX.bmp";
    int fd = mkstemps(path, 4);
    CHECK(fd >= 0);
    if (fd >= 0) close(fd);
    float rgb[2 * 3 * 3] = { 0.5f, 0.0f, 1.0f,  1.0f, 1.0f, 1.0f,  0.0f, 0.0f, 0.0f,
                             0.2f, 0.4f, 0.6f,  2.0f, -1.0f, NAN,  0.25f, 0.5f, 0.75f };
    Error err = {0};
    for (int enc = 0; enc < 2; enc++) {
        CHECK_EQ_INT(image_write_encoded(path, rgb, 3, 2, enc ? IMAGE_LINEAR : IMAGE_SRGB, &err), ST_OK);
        unsigned char b[128];
        FILE *f = fopen(path, "rb");
        size_t n = f ? fread(b, 1, sizeof b, f) : 0;
        if (f) fclose(f);
        CHECK_EQ_INT(n, 54 + 2 * 12);                     /* rows of 9 bytes padded to 12 */
        CHECK(b[0] == 'B' && b[1] == 'M' && b[10] == 54 && b[14] == 40 && b[18] == 3 && b[22] == 2 && b[28] == 24);
        /* the first row in the file is the image's bottom row: (0.2 0.4 0.6) first */
        const unsigned char *bottom = b + 54, *top = b + 54 + 12;
        if (enc) {
            CHECK(bottom[0] == 153 && bottom[1] == 102 && bottom[2] == 51);     /* B G R */
            CHECK(top[0] == 255 && top[1] == 0 && top[2] == 128);
            CHECK(bottom[3] == 0 && bottom[4] == 0 && bottom[5] == 255);      /* NaN 0, clamps */
        } else {
            CHECK(top[2] == image_to_srgb8(0.5f) && top[2] == 188);
        }
        CHECK(bottom[9] == 0 && bottom[10] == 0 && bottom[11] == 0);          /* padding */
    }
    ImageFormat fmt;
    CHECK(image_format_from_path("a.BMP", &fmt, &err) == ST_OK && fmt == IMAGE_BMP);
    CHECK_EQ_INT(image_to_linear8(0.5f), 128);
    CHECK_EQ_INT(image_to_linear8(1.5f), 255);
    unlink(path);
    error_clear(&err);
}

int main(void)
{
    RUN(test_plane_under_point_light);
    RUN(test_devices_agree);
    RUN(test_phong_highlight);
    RUN(test_shadow);
    RUN(test_shadows_off_whitted);
    RUN(test_shadows_off_path);
    RUN(test_directional_and_spot);
    RUN(test_mirror_and_glass);
    RUN(test_refraction);
    RUN(test_aovs);
    RUN(test_pixel_sampling);
    RUN(test_adaptive);
    RUN(test_bmp);
    RUN(test_course_falloff);
    RUN(test_course_camera);
    RUN(test_course_reflection);
    RUN(test_course_mesh_normals);
    RUN(test_course_aovs);
    return harness_report();
}
