/* scene_lights.c — the light list: area lights from the emissive primitives (quads paired),
 * the delta lights and the environment map's light, each chosen in proportion to an
 * estimate of its power (scene_prepare_lights). */
#include "scene/scene.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "base/array.h"
#include "scene/env_dist.h"
#include "scene/instance.h"
#include "scene/motion.h"
#include "scene/transform.h"
#include "util/kmath.h"

Light light_default(uint type)
{
    Light l;
    memset(&l, 0, sizeof l);
    l.type = type;
    l.prim = NO_INDEX;
    l.atten2 = 1.0f;
    l.direction = v3(0.0f, -1.0f, 0.0f);
    l.cos_outer = (float)cos(M_PI / 6.0);
    l.cos_inner = l.cos_outer;
    return l;
}

static int is_emissive(const Scene *s, uint material)
{
    if (material >= s->n_materials) return 0;
    /* any material may emit (a diffuse emitter is what the furnace test needs). An
     * emission texture or an alpha cut-out makes the emitted radiance vary over the
     * surface in a way light sampling does not know: such surfaces are found by BSDF
     * sampling alone (full weight), like the background, which keeps them unbiased. */
    const Material *m = &s->materials[material];
    if (m->texture_emission != NO_INDEX || (m->flags & MAT_ALPHA_ANY)) return 0;
    return v3_luminance(m->emission) > 0.0f;
}

static double triangle_area(const Triangle *t)
{
    vec3 c = v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0));
    return 0.5 * sqrt((double)c.x * c.x + (double)c.y * c.y + (double)c.z * c.z);
}

static int v3_same(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

/* Whether triangles a and b (lights of one material, unit normals na and nb) are the two
 * halves of one parallelogram: they share two corners (the diagonal, bit for bit), b's
 * third corner is the reflection of a's across the diagonal's middle (to 1e-5 of the
 * diagonal), their areas agree to 1e-5 and their winding normals point the same way.
 * Then *corner is a's corner off the diagonal and *e1, *e2 the edges from it, so the
 * parallelogram is corner + s e1 + t e2 over [0,1)^2. */
static int triangles_form_quad(const Triangle *a, const Triangle *b, vec3 na, vec3 nb, vec3 *corner, vec3 *e1,
                               vec3 *e2)
{
    const vec3 pa[3] = { a->p0, a->p1, a->p2 }, pb[3] = { b->p0, b->p1, b->p2 };
    for (int i = 0; i < 3; i++) {
        vec3 d0 = pa[(i + 1) % 3], d1 = pa[(i + 2) % 3];
        int j0 = -1, j1 = -1;
        for (int j = 0; j < 3; j++) {
            if (v3_same(pb[j], d0)) j0 = j;
            else if (v3_same(pb[j], d1)) j1 = j;
        }
        if (j0 < 0 || j1 < 0) continue;
        vec3 far = v3_sub(v3_add(d0, d1), pa[i]), off = v3_sub(pb[3 - j0 - j1], far), diag = v3_sub(d1, d0);
        double off2 = (double)v3_dot(off, off), diag2 = (double)v3_dot(diag, diag);
        double area_a = triangle_area(a), area_b = triangle_area(b);
        if (!(off2 <= 1e-10 * diag2) || !(fabs(area_a - area_b) <= 1e-5 * area_a) || !(area_a > 0.0) ||
            !(v3_dot(na, nb) > 0.0f))
            return 0;
        *corner = pa[i];
        *e1 = v3_sub(d0, pa[i]);
        *e2 = v3_sub(d1, pa[i]);
        return 1;
    }
    return 0;
}

/* Marks consecutive triangle lights [first, end), their normals set, that are the halves
 * of a parallelogram (types.h, LIGHT_QUAD_*) and gives each pair equal power, hence equal
 * choice probabilities, so that the pair's first light-sample coordinate can run across
 * both. */
static void pair_quad_lights(const Scene *s, Light *lights, double *power, size_t first, size_t end)
{
    uint first_tri = scene_first_triangle(s);
    for (size_t k = first; k + 1 < end; k++) {
        const Triangle *a = &s->triangles[lights[k].prim - first_tri];
        const Triangle *b = &s->triangles[lights[k + 1].prim - first_tri];
        vec3 corner, e1, e2;
        if (a->material != b->material ||
            !triangles_form_quad(a, b, lights[k].normal, lights[k + 1].normal, &corner, &e1, &e2))
            continue;
        double mean = 0.5 * (power[k] + power[k + 1]);
        for (size_t h = k; h <= k + 1; h++) {
            lights[h].quad = h == k ? LIGHT_QUAD_FIRST : LIGHT_QUAD_SECOND;
            lights[h].position = corner;
            lights[h].direction = e1;
            lights[h].intensity = e2;
            power[h] = mean;
        }
        k++;
    }
}

static double box_area(const Box *b)
{
    double dx = (double)b->hi.x - b->lo.x, dy = (double)b->hi.y - b->lo.y, dz = (double)b->hi.z - b->lo.z;
    return 2.0 * (dx * dy + dy * dz + dz * dx);
}

/* [lo, hi] grown to hold the ball of radius r about (x, y, z). */
static void bounds_grow(double lo[3], double hi[3], const double c[3], double r)
{
    for (int a = 0; a < 3; a++) {
        if (c[a] - r < lo[a]) lo[a] = c[a] - r;
        if (c[a] + r > hi[a]) hi[a] = c[a] + r;
    }
}

/* [lo, hi] grown by the spheres, triangles and boxes of global ids whose in_object mark
 * is `mark` among [first, end) of each kind (all of them when in_object is NULL). */
static void bounds_of_prims(const Scene *s, const uint8_t *in_object, int mark, const size_t first[OBJ_KINDS],
                            const size_t end[OBJ_KINDS], double lo[3], double hi[3])
{
    uint first_tri = scene_first_triangle(s), first_box = scene_first_box(s);
#define SKIP(gid) (in_object && in_object[gid] != mark)
#define GROW(p, r)                                                                        \
    do {                                                                                  \
        double c_[3] = { (p).x, (p).y, (p).z };                                           \
        bounds_grow(lo, hi, c_, (r));                                                     \
    } while (0)
    for (size_t i = first[OBJ_SPHERES]; i < end[OBJ_SPHERES]; i++)
        if (!SKIP(i)) GROW(s->spheres[i].center, (double)s->spheres[i].radius);
    for (size_t i = first[OBJ_TRIANGLES]; i < end[OBJ_TRIANGLES]; i++) {
        if (SKIP(first_tri + i)) continue;
        GROW(s->triangles[i].p0, 0.0);
        GROW(s->triangles[i].p1, 0.0);
        GROW(s->triangles[i].p2, 0.0);
    }
    for (size_t i = first[OBJ_BOXES]; i < end[OBJ_BOXES]; i++) {
        if (SKIP(first_box + i)) continue;
        GROW(s->boxes[i].lo, 0.0);
        GROW(s->boxes[i].hi, 0.0);
    }
#undef GROW
#undef SKIP
}

/* Radius of the bounding sphere of the finite primitives where the world has them (1
 * when there are none): the size of the region a point or directional light shines on,
 * for its power estimate. An object's primitives count where its instances put them:
 * each instance adds the world box of its object's box's eight corners. */
static Status scene_radius(const Scene *s, const uint8_t *in_object, double *radius, Error *err)
{
    double lo[3] = { INFINITY, INFINITY, INFINITY }, hi[3] = { -INFINITY, -INFINITY, -INFINITY };
    size_t none[OBJ_KINDS] = { 0 }, all[OBJ_KINDS];
    all[OBJ_SPHERES] = s->n_spheres;
    all[OBJ_TRIANGLES] = s->n_triangles;
    all[OBJ_BOXES] = s->n_boxes;
    all[OBJ_REVS] = 0;
    bounds_of_prims(s, in_object, 0, none, all, lo, hi);
    if (s->n_instances) {
        double *box = malloc(s->n_objects * 6 * sizeof *box);
        if (!box) return error_set(err, ST_INTERNAL, "out of memory bounding the instances");
        for (size_t o = 0; o < s->n_objects; o++) {
            double *b = box + 6 * o;
            for (int a = 0; a < 3; a++) b[a] = INFINITY, b[3 + a] = -INFINITY;
            bounds_of_prims(s, NULL, 1, s->objects[o].first, s->objects[o].end, b, b + 3);
        }
        for (size_t i = 0; i < s->n_instances; i++) {
            const Instance *x = &s->instances[i];
            const double *b = box + 6 * s->instance_objects[i];
            if (!(b[3] >= b[0])) continue;
            for (int corner = 0; corner < 8; corner++) {
                double p[3] = { b[(corner & 1) ? 3 : 0], b[(corner & 2) ? 4 : 1], b[(corner & 4) ? 5 : 2] }, w[3];
                for (int r = 0; r < 3; r++)
                    w[r] = (double)x->to_world[4 * r] * p[0] + (double)x->to_world[4 * r + 1] * p[1] +
                           (double)x->to_world[4 * r + 2] * p[2] + (double)x->to_world[4 * r + 3];
                bounds_grow(lo, hi, w, 0.0);
            }
        }
        free(box);
    }
    *radius = 1.0;
    if (!(hi[0] >= lo[0])) return ST_OK;
    double dx = hi[0] - lo[0], dy = hi[1] - lo[1], dz = hi[2] - lo[2];
    double r = 0.5 * sqrt(dx * dx + dy * dy + dz * dz);
    if (r > 0.0 && isfinite(r)) *radius = r;
    return ST_OK;
}

/* Estimated power of a delta light over a scene of radius r (see scene.h). */
static double delta_light_power(const Light *l, double r)
{
    double lum = v3_luminance(l->intensity);
    if (light_has(l->type, LT_INFINITE)) return M_PI * r * r * lum;
    double atten = (double)l->atten0 + (double)l->atten1 * r + (double)l->atten2 * r * r;
    double solid_angle = 4.0 * M_PI;
    if (light_has(l->type, LT_CONE))
        solid_angle = 2.0 * M_PI * (1.0 - 0.5 * ((double)l->cos_inner + (double)l->cos_outer));
    return atten > 0.0 ? solid_angle * r * r * lum / atten : 0.0;
}

Status scene_set_envmap_texels(Scene *s, const uint *texels, uint width, uint height, float intensity, Error *err)
{
    uint offset, index;
    Status st = scene_add_texels(s, texels, 3u * (size_t)width * height, &offset, err);
    if (st) return st;
    Texture t;
    memset(&t, 0, sizeof t);
    t.type = TEX_IMAGE;
    t.flags = TEX_FLOAT;
    t.offset = offset;
    t.width = width;
    t.height = height;
    if ((st = scene_add_texture(s, NULL, NULL, t, &index, err))) return st;
    return scene_set_envmap(s, index, intensity, 0.0f, err);
}

Status scene_set_envmap(Scene *s, uint texture, float intensity, float rotate, Error *err)
{
    const Texture *t = &s->textures[texture];
    if (!(t->flags & TEX_FLOAT))
        return error_set(err, ST_INPUT, "'%s': an environment map must be a high-dynamic-range image (.hdr or "
                         ".exr)", s->texture_sources[texture] ? s->texture_sources[texture] : "");
    /* the guide tables (kernels/light/envmap.h) hold pixel indices as exact floats */
    if (t->width > (1u << 24) || t->height > (1u << 24))
        return error_set(err, ST_INPUT, "'%s': an environment map is at most 16777216 pixels wide and high, not %ux%u",
                         s->texture_sources[texture] ? s->texture_sources[texture] : "", t->width, t->height);
    EnvDist dist;
    Status st = env_dist_build(s->texels + t->offset, t->width, t->height, &dist, err);
    if (st) return st;
    free(s->env_cdf);
    s->env_cdf = dist.cdf;
    s->n_env_cdf = dist.n;
    s->env_mis_dist = dist.mis_offset;
    s->env_mean = dist.mean * (double)intensity;
    if (!(intensity > 0.0f)) {
        /* a black map is no light */
        free(s->env_cdf);
        s->env_cdf = NULL;
        s->n_env_cdf = 0;
        s->env_mis_dist = 0;
    }
    s->bg_type = BG_MAP;
    s->bg_cubemap = texture;
    s->bg_color = v3s(intensity);
    s->bg_zenith = v3s(intensity);
    s->bg_rotate = rotate;
    return ST_OK;
}

/* ------------------------------------------------------------------ instanced emitters */

/* The most lights instanced emitters make (one per instance and emissive triangle, 96
 * bytes each on every device): past it they stay out of the light list, found by BSDF
 * sampling alone, as before they were lights (docs/instancing.md). */
#define MAX_INSTANCED_LIGHTS (1u << 22)

/* The objects' emitters in their object spaces: object o's emissive spheres, then its
 * emissive triangles, are tpl[first[o] .. first[o + 1]) (LIGHT_INSTANCED; a sphere's
 * centre and radius, a triangle's object-space winding normal, quad halves paired as
 * the world's are), and each of them gets its index among its object's as its `light`;
 * every other primitive of an object gets NO_INDEX. Boxes and ellipsoids of objects are
 * no lights: an instance may make a parallelepiped of a box, and light sampling has no
 * density for ellipsoids (the world refuses emitting ones). */
static Status object_emitters(Scene *s, Light **tpl_out, size_t **first_out, Error *err)
{
    *tpl_out = NULL;
    *first_out = NULL;
    size_t *first = malloc((s->n_objects + 1) * sizeof *first);
    size_t n = 0;
    if (!first) return error_set(err, ST_INTERNAL, "out of memory listing the objects' emitters");
    for (size_t o = 0; o < s->n_objects; o++) {
        const SceneObject *ob = &s->objects[o];
        first[o] = n;
        for (size_t i = ob->first[OBJ_SPHERES]; i < ob->end[OBJ_SPHERES]; i++) {
            int emits = s->spheres[i].xform == 0 && is_emissive(s, s->spheres[i].material);
            s->spheres[i].light = emits ? (uint)(n - first[o]) : NO_INDEX;
            n += (size_t)emits;
        }
        for (size_t i = ob->first[OBJ_BOXES]; i < ob->end[OBJ_BOXES]; i++) s->boxes[i].light = NO_INDEX;
        for (size_t i = ob->first[OBJ_TRIANGLES]; i < ob->end[OBJ_TRIANGLES]; i++) {
            int emits = is_emissive(s, s->triangles[i].material);
            s->triangles[i].light = emits ? (uint)(n - first[o]) : NO_INDEX;
            n += (size_t)emits;
        }
    }
    first[s->n_objects] = n;
    Light *tpl = n ? calloc(n, sizeof *tpl) : NULL;
    double *power = n ? calloc(n, sizeof *power) : NULL;
    if (n && (!tpl || !power)) {
        free(first);
        free(tpl);
        free(power);
        return error_set(err, ST_INTERNAL, "out of memory listing the objects' emitters");
    }
    uint first_tri = scene_first_triangle(s);
    for (size_t o = 0; o < s->n_objects; o++) {
        const SceneObject *ob = &s->objects[o];
        size_t tri_lights = first[o];
        for (size_t i = ob->first[OBJ_SPHERES]; i < ob->end[OBJ_SPHERES]; i++) {
            const Sphere *sp = &s->spheres[i];
            if (sp->light == NO_INDEX) continue;
            Light *l = &tpl[first[o] + sp->light];
            l->type = LIGHT_INSTANCED;
            l->prim = (uint)i;
            l->position = sp->center;
            l->atten0 = sp->radius;
            tri_lights++;
        }
        for (size_t i = ob->first[OBJ_TRIANGLES]; i < ob->end[OBJ_TRIANGLES]; i++) {
            const Triangle *t = &s->triangles[i];
            if (t->light == NO_INDEX) continue;
            Light *l = &tpl[first[o] + t->light];
            l->type = LIGHT_INSTANCED;
            l->prim = first_tri + (uint)i;
            l->normal = v3_norm(v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0)));
        }
        pair_quad_lights(s, tpl, power, tri_lights, first[o + 1]);
    }
    free(power);
    *tpl_out = tpl;
    *first_out = first;
    return ST_OK;
}

/* How many lights instance x makes of its object's emitters: none when its
 * material replaces the object's (an emissive one emits where no light record says,
 * found by BSDF sampling alone; a dark one does not emit). A moving instance makes
 * them too, placed at each path's time by the kernels (LIGHT_MOVING). */
static size_t instance_light_count(const Instance *x, uint object, const size_t *first)
{
    if (x->material != NO_INDEX) return 0;
    return first[object + 1] - first[object];
}

/* Whether every key of a moving transform is a similarity: its stretch S (M = T R S,
 * types.h MotionKey) s I, within 1e-5 of s, with s of one sign at every key. Between
 * such keys the kernels interpolate S linearly (a multiple of I again) and R by slerp,
 * so the transform at any time is a similarity and carries a sphere to a sphere. */
static int keys_are_similarities(const MotionKey *keys)
{
    double s0 = keys[0].stretch[0];
    for (uint k = 0; k < keys[0].count; k++) {
        const float *st = keys[k].stretch;    /* s00 s01 s02 s11 s12 s22 */
        double sk = st[0], tol = 1e-5 * fabs(sk);
        if (!(sk * s0 > 0.0) || !(fabs(st[3] - sk) <= tol) || !(fabs(st[5] - sk) <= tol) ||
            !(fabs(st[1]) <= tol) || !(fabs(st[2]) <= tol) || !(fabs(st[4]) <= tol))
            return 0;
    }
    return 1;
}

/* The scale s when the linear part of m is s times a rotation (or a mirror), each
 * column's length and each pair's dot product within 1e-5 of s^2's; else 0. */
static double similarity_scale(double m[3][4])
{
    double g[3][3];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) g[i][j] = m[0][i] * m[0][j] + m[1][i] * m[1][j] + m[2][i] * m[2][j];
    double s2 = (g[0][0] + g[1][1] + g[2][2]) / 3.0;
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            if (!(fabs(g[i][j] - (i == j ? s2 : 0.0)) <= 1e-5 * s2)) return 0.0;
    return sqrt(s2);
}

/* Sphere template tpl under m: under a similarity the world sphere (centre M c, radius
 * s r) that light sampling samples by its cone (kernels/light/lights.h); under any other
 * map an ellipsoid, whose light keeps no area and so no power: it is never chosen, and
 * a hit on it, whose density is then 0, counts at BSDF sampling's full weight. */
static Light instanced_sphere_light(const Light *tpl, double m[3][4], double *area)
{
    Light l = *tpl;
    double scale = similarity_scale(m), c[3] = { tpl->position.x, tpl->position.y, tpl->position.z }, w[3];
    for (int r = 0; r < 3; r++) w[r] = m[r][0] * c[0] + m[r][1] * c[1] + m[r][2] * c[2] + m[r][3];
    double radius = scale * tpl->atten0;
    *area = 4.0 * M_PI * radius * radius;
    l.position = v3((float)w[0], (float)w[1], (float)w[2]);
    l.atten0 = (float)radius;
    l.area = (float)*area;
    return l;
}

/* Template tpl (object space) as instance x places it (types.h, LIGHT_INSTANCED): the
 * world corner and edges of its triangle, or of its quad's parallelogram, computed in
 * double and rounded once; the normal by M^-T; the area of the world triangle, which
 * *area gets in double. An affine map carries the uniform density on the object's
 * triangle to the uniform density on the world's, so 1 / area is the sample's density. */
static Light instanced_light(const Scene *s, const Light *tpl, const Instance *x, double *area)
{
    double m[3][4], nm[3][3];
    Transform t;
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 4; c++) t.m[r][c] = m[r][c] = (double)x->to_world[4 * r + c];
    if (tpl->prim < scene_first_triangle(s)) return instanced_sphere_light(tpl, m, area);
    double c0[3], e1[3], e2[3];
    if (tpl->quad != LIGHT_QUAD_NONE) {
        const vec3 a = tpl->position, b = tpl->direction, c = tpl->intensity;
        double cc[3] = { a.x, a.y, a.z }, bb[3] = { b.x, b.y, b.z }, dd[3] = { c.x, c.y, c.z };
        memcpy(c0, cc, sizeof c0);
        memcpy(e1, bb, sizeof e1);
        memcpy(e2, dd, sizeof e2);
    } else {
        const Triangle *tr = &s->triangles[tpl->prim - scene_first_triangle(s)];
        double p0[3] = { tr->p0.x, tr->p0.y, tr->p0.z }, p1[3] = { tr->p1.x, tr->p1.y, tr->p1.z },
               p2[3] = { tr->p2.x, tr->p2.y, tr->p2.z };
        for (int a = 0; a < 3; a++) c0[a] = p0[a], e1[a] = p1[a] - p0[a], e2[a] = p2[a] - p0[a];
    }
    double wc[3], w1[3], w2[3];
    for (int r = 0; r < 3; r++) {
        wc[r] = m[r][0] * c0[0] + m[r][1] * c0[1] + m[r][2] * c0[2] + m[r][3];
        w1[r] = m[r][0] * e1[0] + m[r][1] * e1[1] + m[r][2] * e1[2];
        w2[r] = m[r][0] * e2[0] + m[r][1] * e2[1] + m[r][2] * e2[2];
    }
    double cx = w1[1] * w2[2] - w1[2] * w2[1], cy = w1[2] * w2[0] - w1[0] * w2[2], cz = w1[0] * w2[1] - w1[1] * w2[0];
    *area = 0.5 * sqrt(cx * cx + cy * cy + cz * cz);
    Light l = *tpl;
    l.position = v3((float)wc[0], (float)wc[1], (float)wc[2]);
    l.direction = v3((float)w1[0], (float)w1[1], (float)w1[2]);
    l.intensity = v3((float)w2[0], (float)w2[1], (float)w2[2]);
    l.area = (float)*area;
    if (transform_normal_matrix(&t, nm)) {
        vec3 n = tpl->normal;
        double v[3];
        for (int r = 0; r < 3; r++) v[r] = nm[r][0] * n.x + nm[r][1] * n.y + nm[r][2] * n.z;
        double len = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (len > 0.0) l.normal = v3((float)(v[0] / len), (float)(v[1] / len), (float)(v[2] / len));
    }
    return l;
}

/* Template tpl (object space) of moving instance i, whose keys start at `keys`, as a
 * LIGHT_MOVING record (types.h): the object-space corner and edges (or sphere) the
 * kernels place at each path's time, and the instance. Its `area` is its first pose's
 * (the instance record's M), as a still instance's light would have; a sphere's is its
 * object-space area, which light_moving_at scales with the radius. *area gets, in
 * double, its mean area over the shutter (motion_mean_area), which sets its power: the
 * choice among lights is one distribution for the whole shutter, and a path's time is
 * uniform over it, so a lamp that grows is chosen in proportion to the light it gives
 * on average, not at the opening (docs/motion.md, Moving emitters). A sphere whose
 * instance is not a similarity at every key is an ellipsoid somewhere: area 0, never
 * chosen, found by BSDF sampling at full weight (as a still instance's,
 * instanced_sphere_light). */
static Light moving_light(const Scene *s, const Light *tpl, uint i, const MotionKey *keys, double *area)
{
    Light l = instanced_light(s, tpl, &s->instances[i], area);
    uint first_tri = scene_first_triangle(s);
    double open = s->camera.shutter_open, close = s->camera.shutter_close;
    l.type = LIGHT_MOVING;
    l.spot_falloff = i;    /* light_instance */
    if (tpl->prim < first_tri) {
        l.position = tpl->position;
        l.atten0 = tpl->atten0;
        if (!keys_are_similarities(keys)) {
            *area = 0.0;
            l.area = 0.0f;
            return l;
        }
        /* under a similarity s(t) I the sphere's area is 4 pi r^2 s(t)^2, and s(t)^2 is
         * the area the stretch gives a unit square */
        const double ex[3] = { 1.0, 0.0, 0.0 }, ey[3] = { 0.0, 1.0, 0.0 };
        double r = tpl->atten0;
        *area = 4.0 * M_PI * r * r * motion_mean_area(keys, keys[0].count, open, close, ex, ey);
        /* the object-space area: light_moving_at scales it by s(t)^2 with the radius */
        l.area = (float)(4.0 * M_PI * r * r);
        return l;
    }
    l.normal = tpl->normal;
    if (tpl->quad != LIGHT_QUAD_NONE) {
        l.position = tpl->position;
        l.direction = tpl->direction;
        l.intensity = tpl->intensity;
    } else {
        const Triangle *tr = &s->triangles[tpl->prim - first_tri];
        l.position = tr->p0;
        l.direction = v3_sub(tr->p1, tr->p0);
        l.intensity = v3_sub(tr->p2, tr->p0);
    }
    /* half the parallelogram of its two edges, as instanced_light's area */
    const double e1[3] = { l.direction.x, l.direction.y, l.direction.z },
                 e2[3] = { l.intensity.x, l.intensity.y, l.intensity.z };
    *area = 0.5 * motion_mean_area(keys, keys[0].count, open, close, e1, e2);
    return l;
}

Status scene_prepare_lights(Scene *s, Error *err)
{
    free(s->lights);
    free(s->instance_lights);
    s->lights = NULL;
    s->instance_lights = NULL;
    s->n_lights = 0;
    s->env_light = NO_INDEX;
    int env = s->bg_type == BG_MAP && s->n_env_cdf > 0;
    size_t n = (size_t)env;
    /* an object's primitives are in no place of the world until instanced: they become
     * lights once per instance, after the world's own (docs/instancing.md) */
    uint8_t *in_object;
    Status st = scene_object_mask(s, &in_object, err);
    if (st) return st;
    uint first_tri = scene_first_triangle(s), first_box = scene_first_box(s);
#define IN_OBJECT(gid) (in_object && in_object[gid])
    for (size_t i = 0; i < s->n_spheres; i++) {
        if (IN_OBJECT(i)) continue;
        /* the kernels sample sphere lights by the cone a sphere subtends: an ellipsoid
         * has none (the pbrt reader makes emitting ones meshes) */
        if (s->spheres[i].xform && is_emissive(s, s->spheres[i].material)) {
            free(in_object);
            return error_set(err, ST_INPUT, "sphere %zu is an ellipsoid that emits light, which clpt cannot "
                             "sample; make it a mesh", i);
        }
        n += (size_t)is_emissive(s, s->spheres[i].material);
    }
    for (size_t i = 0; i < s->n_triangles; i++)
        n += (size_t)(is_emissive(s, s->triangles[i].material) && !IN_OBJECT(first_tri + i));
    for (size_t i = 0; i < s->n_boxes; i++)
        n += (size_t)(is_emissive(s, s->boxes[i].material) && !IN_OBJECT(first_box + i));
    Light *tpl = NULL;
    size_t *tpl_first = NULL, n_instanced = 0;
    if (s->n_instances) {
        if ((st = object_emitters(s, &tpl, &tpl_first, err))) {
            free(in_object);
            return st;
        }
        for (size_t i = 0; i < s->n_instances; i++) n_instanced += instance_light_count(&s->instances[i], s->instance_objects[i], tpl_first);
        if (n_instanced > MAX_INSTANCED_LIGHTS) n_instanced = 0;
        if (n_instanced) s->instance_lights = malloc(s->n_instances * sizeof *s->instance_lights);
        if (n_instanced == 0 || !s->instance_lights) {
            /* no instance's emitters are lights: none may name one (surface_instanced
             * reads instance_lights, which is then empty) */
            for (size_t o = 0; o < s->n_objects; o++) {
                for (size_t i = s->objects[o].first[OBJ_SPHERES]; i < s->objects[o].end[OBJ_SPHERES]; i++)
                    s->spheres[i].light = NO_INDEX;
                for (size_t i = s->objects[o].first[OBJ_TRIANGLES]; i < s->objects[o].end[OBJ_TRIANGLES]; i++)
                    s->triangles[i].light = NO_INDEX;
            }
            if (n_instanced) {
                free(in_object);
                free(tpl);
                free(tpl_first);
                return error_set(err, ST_INTERNAL, "out of memory listing the instances' lights");
            }
        }
    }
    n += n_instanced;
    n += s->n_delta_lights;
    Light *lights = NULL;
    double *power = NULL;
    if (n == 0 || n >= (size_t)NO_INDEX) {
        st = n == 0 ? ST_OK : error_set(err, ST_INPUT, "too many emissive primitives");
        goto done;
    }
    lights = calloc(n, sizeof *lights);
    power = calloc(n, sizeof *power);
    if (!lights || !power) {
        st = error_set(err, ST_INTERNAL, "out of memory building the light list");
        goto done;
    }
    size_t k = 0;
    double total = 0.0;
#define ADD_LIGHT(arr, count, first, area_expr)                                          \
    for (size_t i = 0; i < (count); i++) {                                                \
        if (!is_emissive(s, arr[i].material) || IN_OBJECT((first) + i)) continue;         \
        double area = (area_expr);                                                        \
        lights[k].type = LIGHT_AREA;                                                      \
        lights[k].prim = (uint)((first) + i);                                             \
        lights[k].area = (float)area;                                                     \
        power[k] = M_PI * area * v3_luminance(s->materials[arr[i].material].emission);   \
        total += power[k];                                                                \
        arr[i].light = (uint)k;                                                           \
        k++;                                                                              \
    }
    ADD_LIGHT(s->spheres, s->n_spheres, 0, 4.0 * M_PI * (double)s->spheres[i].radius * s->spheres[i].radius)
    size_t first_tri_light = k;
    ADD_LIGHT(s->triangles, s->n_triangles, first_tri, triangle_area(&s->triangles[i]))
    for (size_t j = first_tri_light; j < k; j++) {
        /* the normal surface_at computes for the triangle: the same float operations */
        const Triangle *t = &s->triangles[lights[j].prim - first_tri];
        lights[j].normal = v3_norm(v3_cross(v3_sub(t->p1, t->p0), v3_sub(t->p2, t->p0)));
    }
    pair_quad_lights(s, lights, power, first_tri_light, k);
    ADD_LIGHT(s->boxes, s->n_boxes, first_box, box_area(&s->boxes[i]))
#undef IN_OBJECT
#undef ADD_LIGHT
    for (size_t i = 0; n_instanced && i < s->n_instances; i++) {
        const Instance *x = &s->instances[i];
        size_t count = instance_light_count(x, s->instance_objects[i], tpl_first);
        s->instance_lights[i] = count ? (uint)k : NO_INDEX;
        for (size_t j = 0; j < count; j++, k++) {
            const Light *t = &tpl[tpl_first[s->instance_objects[i]] + j];
            double area;
            uint key0 = i < s->n_instance_motion ? s->instance_motion[i] : NO_INDEX;
            if ((x->flags & INST_MOTION) && key0 != NO_INDEX)
                lights[k] = moving_light(s, t, (uint)i, s->motion_keys + key0, &area);
            else
                lights[k] = instanced_light(s, t, x, &area);
            uint material = t->prim < first_tri ? s->spheres[t->prim].material
                                                : s->triangles[t->prim - first_tri].material;
            power[k] = M_PI * area * v3_luminance(s->materials[material].emission);
            if (!(power[k] >= 0.0) || !isfinite(power[k])) power[k] = 0.0;
            total += power[k];
        }
    }
    double radius = 1.0;
    if ((s->n_delta_lights || env) && (st = scene_radius(s, in_object, &radius, err))) goto done;
    for (size_t i = 0; i < s->n_delta_lights; i++, k++) {
        lights[k] = s->delta_lights[i];
        lights[k].prim = NO_INDEX;
        power[k] = delta_light_power(&s->delta_lights[i], radius);
        if (!(power[k] >= 0.0) || !isfinite(power[k])) power[k] = 0.0;
        total += power[k];
    }
    if (env) {
        lights[k].type = LIGHT_ENV;
        lights[k].prim = NO_INDEX;
        power[k] = M_PI * s->env_mean * 4.0 * M_PI * radius * radius;
        if (!(power[k] >= 0.0) || !isfinite(power[k])) power[k] = 0.0;
        total += power[k];
        s->env_light = (uint)k++;
    }
    /* Degenerate or black lights get zero power; if all are, choose uniformly so the
     * distribution stays valid. */
    double acc = 0.0;
    for (size_t i = 0; i < n; i++) {
        double p = total > 0.0 ? power[i] / total : 1.0 / (double)n;
        acc += p;
        lights[i].pick_pdf = (float)p;
        lights[i].cdf = (float)acc;
    }
    lights[n - 1].cdf = 1.0f;  /* exact top so a uniform sample in [0,1) always lands */
    s->lights = lights;
    s->n_lights = n;
    lights = NULL;
done:
    free(lights);
    free(power);
    free(in_object);
    free(tpl);
    free(tpl_first);
    return st;
}
