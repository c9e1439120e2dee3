/*
 * shade_lanes.h — one bounce of eight paths at once, for CPUs (OpenCL only).
 *
 * PoCL cannot vectorise shade_path across work-items (bench/RESULTS.md: clang's SLP
 * vectoriser turns its vec3 arithmetic into 2-wide vectors first, and LLVM's loop
 * vectoriser then refuses the work-item loop), so shading ran one path at a time while
 * the traversal used eight lanes. Here a work-item holds eight paths (k_path_lanes,
 * entry.cl), and the common case, a flat triangle of a plain diffuse material whose
 * light sample picks a triangle lamp, with the Sobol sampler, MIS and shadows on, is
 * shaded as float8 arithmetic and the sampler as uint8: the same operations as
 * shade_path in the same order, branches as selects, each lane rounded as the scalar
 * would be, so every lane computes the bits shade_path computes (test_kernels compares
 * them). The gathers, the light choice and the stores stay per lane. The other lanes
 * end their paths (shade_lane_end): the host runs k_path_lanes only for scenes in
 * which nothing else can happen.
 */
#ifndef CLPT_SHADE_LANES_H
#define CLPT_SHADE_LANES_H

#include "integrator/shade_path.h"

typedef struct { float8 x, y, z; } vec3x8;

KFN_INLINE vec3x8 w3(float8 x, float8 y, float8 z) { vec3x8 r; r.x = x; r.y = y; r.z = z; return r; }
KFN_INLINE vec3x8 w3_add(vec3x8 a, vec3x8 b) { return w3(a.x + b.x, a.y + b.y, a.z + b.z); }
KFN_INLINE vec3x8 w3_sub(vec3x8 a, vec3x8 b) { return w3(a.x - b.x, a.y - b.y, a.z - b.z); }
KFN_INLINE vec3x8 w3_mul(vec3x8 a, vec3x8 b) { return w3(a.x * b.x, a.y * b.y, a.z * b.z); }
KFN_INLINE vec3x8 w3_scale(vec3x8 a, float8 s) { return w3(a.x * s, a.y * s, a.z * s); }
KFN_INLINE vec3x8 w3_neg(vec3x8 a) { return w3(-a.x, -a.y, -a.z); }
KFN_INLINE float8 w3_dot(vec3x8 a, vec3x8 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
KFN_INLINE vec3x8 w3_cross(vec3x8 a, vec3x8 b)
{
    return w3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
/* per lane: b where m is set (-1), else a */
KFN_INLINE vec3x8 w3_select(vec3x8 a, vec3x8 b, int8 m)
{
    return w3(select(a.x, b.x, m), select(a.y, b.y, m), select(a.z, b.z, m));
}
/* k_fmin / k_fmax lane by lane (compat.h: a NaN argument loses) */
KFN_INLINE float8 w_fmin(float8 a, float8 b) { return select(a, b, (b < a) | (a != a)); }
KFN_INLINE float8 w_fmax(float8 a, float8 b) { return select(a, b, (b > a) | (a != a)); }
KFN_INLINE float8 w3_max_comp(vec3x8 a) { return w_fmax(a.x, w_fmax(a.y, a.z)); }
KFN_INLINE float8 w_copysign(float8 mag, float8 sgn)
{
    return as_float8((as_uint8(mag) & 0x7fffffffu) | (as_uint8(sgn) & 0x80000000u));
}

KFN_INLINE vec3x8 w3_abs(vec3x8 a) { return w3(fabs(a.x), fabs(a.y), fabs(a.z)); }
KFN_INLINE float8 w3_max_abs(vec3x8 a) { return w_fmax(fabs(a.x), w_fmax(fabs(a.y), fabs(a.z))); }

/* triangle_point_error (surface.h) lane by lane */
KFN_INLINE vec3x8 w_triangle_point_error(vec3x8 p0, vec3x8 p1, vec3x8 p2, float8 w, float8 u, float8 v, vec3x8 p)
{
    vec3x8 sum = w3_add(w3_add(w3_abs(w3_scale(p0, w)), w3_abs(w3_scale(p1, u))), w3_abs(w3_scale(p2, v)));
    float8 extent = w_fmax(w3_max_abs(w3_sub(p0, p)), w_fmax(w3_max_abs(w3_sub(p1, p)), w3_max_abs(w3_sub(p2, p))));
    float8 ext_err = K_ROUND_ERR(16) * extent;
    vec3x8 e = w3_scale(sum, (float8)(K_ROUND_ERR(7)));
    return w3(e.x + ext_err, e.y + ext_err, e.z + ext_err);
}

/* spawn_offset (surface.h) lane by lane */
KFN_INLINE vec3x8 w_spawn_offset(vec3x8 p, vec3x8 err, vec3x8 n)
{
    vec3x8 an = w3_abs(n);
    float8 d = w3_dot(an, err);
    float8 dist = d + SPAWN_MARGIN * (w3_dot(an, w3_abs(p)) + d) + SPAWN_FLOOR;
    return w3_add(p, w3_scale(n, dist));
}

/* sample_cosine_hemisphere (sampling.h) lane by lane, through sample_disk's selects */
KFN_INLINE vec3x8 w_sample_cosine_hemisphere(float8 u1, float8 u2)
{
    float8 a = 2.0f * u1 - 1.0f, b = 2.0f * u2 - 1.0f;
    int8 zero = (a == 0.0f) & (b == 0.0f);
    int8 about_x = a * a > b * b;
    float8 r = select(b, a, about_x);
    float8 t = 0.785398163f * (select(a, b, about_x) / r);
    float8 t2 = t * t;
    float8 s = K_SIN_QUARTER(t, t2), c = K_COS_QUARTER(t2);
    float8 x = select(r * select(s, c, about_x), 0.0f, zero);
    float8 y = select(r * select(c, s, about_x), 0.0f, zero);
    return w3(x, y, sqrt(w_fmax(1.0f - x * x - y * y, 0.0f)));
}

/* k_onb and k_to_world (kmath.h) lane by lane */
KFN_INLINE vec3x8 w_to_world_onb(vec3x8 v, vec3x8 n)
{
    float8 sign = w_copysign((float8)(1.0f), n.z);
    float8 a = -1.0f / (sign + n.z);
    float8 bb = n.x * n.y * a;
    vec3x8 t = w3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    vec3x8 b = w3(bb, sign + n.y * n.y * a, -n.y);
    return w3_add(w3_add(w3_scale(t, v.x), w3_scale(b, v.y)), w3_scale(n, v.z));
}

/* The Sobol sampler of rng.h lane by lane (uint8), through its own steps; the byte
 * swap as shifts, which do what bswap does. */
KFN_INLINE uint8 w_rng_hash(uint8 x)
{
    RNG_HASH_STEPS(x);
    return x;
}
KFN_INLINE uint8 w_reverse_bits(uint8 x)
{
    RNG_SWAP_BYTES_STEPS(x);
    RNG_REVERSE_IN_BYTES_STEPS(x);
    return x;
}
KFN_INLINE uint8 w_lk_permute(uint8 x, uint8 seed)
{
    RNG_LK_PERMUTE_STEPS(x, seed);
    return x;
}
KFN_INLINE uint8 w_sobol1_reversed(uint8 index)
{
    RNG_SOBOL1_STEPS(index);
    return index;
}
KFN_INLINE float8 w_rng_to_float(uint8 h) { return convert_float8(h >> 8) * RNG_FLOAT_SCALE; }
/* rng_uniform2 (coord 0 and 1 of a pair's pattern) or rng_uniform of a 1D dimension
 * (coord 0 only) for keys `key`, reversed sample indices `rev`, bounces `bounce` */
KFN_INLINE void w_rng_pair(uint8 key, uint8 rev, uint8 bounce, uint first, float8 *u, float8 *v)
{
    uint8 pattern = w_rng_hash(key + (bounce * (uint)RNG_DIMS_PER_BOUNCE + first) * RNG_PATTERN_STEP);
    uint8 index = w_reverse_bits(w_lk_permute(rev, pattern));
    *u = w_rng_to_float(w_reverse_bits(w_lk_permute(index, pattern * RNG_COORD0_SEED_MUL + RNG_COORD_SEED_ADD)));
    if (v)
        *v = w_rng_to_float(
            w_reverse_bits(w_lk_permute(w_sobol1_reversed(index), pattern * RNG_COORD1_SEED_MUL + RNG_COORD_SEED_ADD)));
}

/* The vector shading's inputs, gathered lane by lane; every field is eight words, so
 * shade_lanes clears the whole as float8 stores. */
typedef float LaneFloats[PATH_LANES];
typedef struct {
    LaneFloats dx, dy, dz;                                    /* the ray's direction */
    LaneFloats hu, hv;                                        /* barycentrics */
    LaneFloats p0x, p0y, p0z, p1x, p1y, p1z, p2x, p2y, p2z;   /* the triangle */
    LaneFloats ar, ag, ab;                                    /* albedo */
    LaneFloats tr, tg, tb;                                    /* throughput */
    LaneFloats lax, lay, laz, lbx, lby, lbz, lcx, lcy, lcz;   /* lamp: a quad's corner and
                                                               * edges, a triangle's corners */
    int lquad[PATH_LANES];                                    /* -1: a quad lamp */
    LaneFloats lsq0, lrest, lv;                               /* a quad half's start; the light
                                                               * pair's rest of u, and v */
    LaneFloats lnx, lny, lnz;                                 /* the lamp's normal */
    LaneFloats ler, leg, leb;                                 /* its radiance */
    LaneFloats larea, lchoice;                                /* its area, choice probability */
    int ltwo[PATH_LANES];                                     /* -1: a two-sided lamp */
    int rr[PATH_LANES];                                       /* -1: roulette at this bounce */
    uint key[PATH_LANES], rev[PATH_LANES], bounce[PATH_LANES];  /* RngKey.key, .sample_rev */
    LaneFloats bsplit;                                        /* RenderParams.split */
} LaneInputs;

/* Whether the path's hit is one shade_lanes_fast can shade (a flat triangle of an
 * untextured, non-emitting diffuse material, below the last bounce), and if so lane l
 * of `in` gets its surface, path and sampler inputs. */
KFN_INLINE int lane_surface(const SceneView *sc, GLOBAL const Ray *ray, Hit hit, GLOBAL const PathState *ps,
                            LaneInputs *in, uint l)
{
    GLOBAL const RenderParams *p = sc->params;
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    if (hit.prim == NO_INDEX || hit.prim < first_tri || hit.prim >= first_box) return 0;
    if (hit.inst != NO_INDEX) return 0;   /* (kernel_lanes_scene keeps instances away) */
    uint bounce = ps->bounce;
    if (bounce >= p->max_depth) return 0;
    GLOBAL const Triangle *tri = &sc->triangles[hit.prim - first_tri];
    if (tri->shading != NO_INDEX) return 0;
    GLOBAL const Material *m = &sc->materials[tri->material];
    if (m->type != MAT_DIFFUSE || !v3_is_zero(m->emission)) return 0;
    if (KF_HAS(KF_TEXTURES) && (m->texture != NO_INDEX || m->texture_emission != NO_INDEX)) return 0;
    in->dx[l] = ray->d.x; in->dy[l] = ray->d.y; in->dz[l] = ray->d.z;
    in->hu[l] = hit.u; in->hv[l] = hit.v;
    in->p0x[l] = tri->p0.x; in->p0y[l] = tri->p0.y; in->p0z[l] = tri->p0.z;
    in->p1x[l] = tri->p1.x; in->p1y[l] = tri->p1.y; in->p1z[l] = tri->p1.z;
    in->p2x[l] = tri->p2.x; in->p2y[l] = tri->p2.y; in->p2z[l] = tri->p2.z;
    in->ar[l] = m->albedo.x; in->ag[l] = m->albedo.y; in->ab[l] = m->albedo.z;
    vec3 thr = ps->throughput;
    if (bounce == 0u && p->split > 1u) thr = v3_scale(thr, 1.0f / (float)p->split);   /* as shade_path */
    in->tr[l] = thr.x; in->tg[l] = thr.y; in->tb[l] = thr.z;
    in->rr[l] = bounce + 1u > p->rr_depth ? -1 : 0;
    in->key[l] = ps->rng_key;
    in->rev[l] = rng_reverse_bits(ps->sample * params_split(p) + ps->branch);
    in->bounce[l] = bounce;
    in->bsplit[l] = (float)params_split(p);
    return 1;
}

/* The light lane l's sample chooses with its light pair's first coordinate lu
 * (light_sample_in, reusing the rest of it): whether shade_lanes_fast can sample it
 * (an area light on a triangle), and if so lane l of `in` gets the light's points (a
 * quad's corner and edges, or a triangle's corners), normal, radiance and densities. */
KFN_INLINE int lane_light(const SceneView *sc, float lu, LaneInputs *in, uint l)
{
    GLOBAL const RenderParams *p = sc->params;
    uint first_tri = p->n_spheres, first_box = first_tri + p->n_triangles;
    float u_rest;
    GLOBAL const Light *lt = &sc->lights[light_choose(sc, lu * 1.0f, &u_rest)];
    if (lt->type != LIGHT_AREA || lt->prim < first_tri || lt->prim >= first_box) return 0;
    GLOBAL const Triangle *ltr = &sc->triangles[lt->prim - first_tri];
    int quad = lt->quad != LIGHT_QUAD_NONE;
    vec3 a = quad ? lt->position : ltr->p0, b = quad ? lt->direction : ltr->p1, c = quad ? lt->intensity : ltr->p2;
    GLOBAL const Material *lm = &sc->materials[ltr->material];
    in->lax[l] = a.x; in->lay[l] = a.y; in->laz[l] = a.z;
    in->lbx[l] = b.x; in->lby[l] = b.y; in->lbz[l] = b.z;
    in->lcx[l] = c.x; in->lcy[l] = c.y; in->lcz[l] = c.z;
    in->lquad[l] = quad ? -1 : 0;
    in->lsq0[l] = lt->quad == LIGHT_QUAD_SECOND ? 0.5f : 0.0f;
    in->lrest[l] = u_rest;
    in->lnx[l] = lt->normal.x; in->lny[l] = lt->normal.y; in->lnz[l] = lt->normal.z;
    in->ler[l] = lm->emission.x; in->leg[l] = lm->emission.y; in->leb[l] = lm->emission.z;
    in->larea[l] = lt->area;
    in->lchoice[l] = lt->pick_pdf / 1.0f;
    in->ltwo[l] = (lm->flags & MAT_TWO_SIDED) ? -1 : 0;
    return 1;
}

#define LANE_LOAD(name) vload8(0, in->name)
#define LANE_LOAD3(a, b, c) w3(vload8(0, in->a), vload8(0, in->b), vload8(0, in->c))

/* The lanes' results, scattered per lane by the caller. */
typedef struct {
    float8 ox, oy, oz, dx, dy, dz;                 /* next ray */
    float8 sox, soy, soz, sdx, sdy, sdz, stmax;    /* shadow ray */
    float8 lr, lg, lb;                             /* shadow_L */
    float8 tr, tg, tb, pdf;                        /* throughput, bsdf_pdf */
    int8 shadow, advance, cont;                    /* -1 where: a shadow ray; bounce + 1; goes on */
} LaneResults;

/* shade_path for eight gathered lanes of the common case (see the top of this file).
 * A call on CPUs (KFN_CALL_CL): PoCL built k_path_lanes in 2.9 s with this and
 * shade_lanes inlined, in 1.8 s with them as calls, at the same speed. */
KFN_CALL_CL void shade_lanes_fast(const LaneInputs *in, LaneResults *out)
{
    /* surface_at: the triangle's point by barycentrics and its winding normal, which is
     * also the shading normal (flat triangles only) */
    float8 u = LANE_LOAD(hu), v = LANE_LOAD(hv);
    float8 w = 1.0f - u - v;
    vec3x8 p0 = LANE_LOAD3(p0x, p0y, p0z), p1 = LANE_LOAD3(p1x, p1y, p1z), p2 = LANE_LOAD3(p2x, p2y, p2z);
    vec3x8 sp = w3_add(w3_add(w3_scale(p0, w), w3_scale(p1, u)), w3_scale(p2, v));
    vec3x8 ng = w3_cross(w3_sub(p1, p0), w3_sub(p2, p0));
    ng = w3_select(ng, w3_scale(ng, (float8)(TRI_NORMAL_SCALE)), ~(w3_dot(ng, ng) < INFINITY));   /* triangle_normal */
    ng = w3_scale(ng, 1.0f / sqrt(w3_dot(ng, ng)));
    vec3x8 d = LANE_LOAD3(dx, dy, dz);
    int8 front = w3_dot(d, ng) < 0.0f;
    vec3x8 ng_face = w3_select(w3_neg(ng), ng, front);
    vec3x8 albedo = LANE_LOAD3(ar, ag, ab);
    vec3x8 thr0 = LANE_LOAD3(tr, tg, tb);

    /* shade_light_sample through light_sample_area and light_pdf_by_area: the point on
     * a quad (a parallelogram) or a triangle (sample_triangle) */
    vec3x8 la = LANE_LOAD3(lax, lay, laz), lb = LANE_LOAD3(lbx, lby, lbz), lc = LANE_LOAD3(lcx, lcy, lcz);
    float8 u1 = LANE_LOAD(lrest), u2 = LANE_LOAD(lv);
    float8 sq = LANE_LOAD(lsq0) + 0.5f * u1;
    vec3x8 on_quad = w3_add(la, w3_add(w3_scale(lb, sq), w3_scale(lc, u2)));
    float8 su = sqrt(u1);
    float8 b1 = 1.0f - su, b2 = u2 * su;
    vec3x8 on_tri = w3_add(w3_add(w3_scale(la, 1.0f - b1 - b2), w3_scale(lb, b1)), w3_scale(lc, b2));
    vec3x8 lp = w3_select(on_tri, on_quad, vload8(0, in->lquad)), ln = LANE_LOAD3(lnx, lny, lnz);
    vec3x8 to = w3_sub(lp, sp);
    float8 dist2 = w3_dot(to, to);
    float8 dist = sqrt(dist2);
    int8 ok = dist > 0.0f;
    float8 inv_dist = 1.0f / dist;
    vec3x8 wi = w3_scale(to, inv_dist);
    float8 area = LANE_LOAD(larea);
    float8 cos_l = fabs(w3_dot(ln, to)) * inv_dist;
    float8 lpdf = select(dist2 / (cos_l * area), 0.0f, (cos_l <= 0.0f) | (area <= 0.0f));
    int8 faces = vload8(0, in->ltwo) | (w3_dot(ln, w3_sub(sp, lp)) > 0.0f);
    ok &= (lpdf > 0.0f) & faces;
    lpdf = lpdf * LANE_LOAD(lchoice);
    ok &= lpdf > 0.0f;
    float8 cos_s = w3_dot(ng_face, wi);   /* the shading normal's cosine ... */
    float8 cos_g = cos_s;                 /* ... and the geometric one: the same here */
    ok &= (cos_s != 0.0f) & ~(cos_s < 0.0f) & ~(cos_g <= 0.0f);
    /* bsdf_eval of the diffuse lobe */
    int8 no_f = cos_s <= 0.0f;
    float8 bpdf = select(cos_s * K_INV_PI, 0.0f, no_f);
    float8 zero = 0.0f;
    vec3x8 f = w3_select(w3_scale(albedo, (float8)(K_INV_PI)), w3(zero, zero, zero), no_f);
    float8 pa2 = lpdf * lpdf, pb2 = bpdf * bpdf;
    float8 mis = select(0.0f, pa2 / (pa2 + pb2), pa2 + pb2 > 0.0f);   /* mis_power */
    vec3x8 f_cos = w3_scale(f, cos_s * mis / lpdf);
    vec3x8 L = w3_mul(w3_mul(thr0, f_cos), LANE_LOAD3(ler, leg, leb));
    vec3x8 o = w_spawn_offset(sp, w_triangle_point_error(p0, p1, p2, w, u, v, sp), ng_face);
    vec3x8 target = w_spawn_offset(lp, w3_scale(w3_abs(lp), (float8)(K_ROUND_ERR(8))),
                                   w3_select(ln, w3_neg(ln), w3_dot(ln, wi) > 0.0f));
    int8 infinite = ~(dist < INFINITY);
    vec3x8 sd = w3_select(w3_sub(target, o), wi, infinite);
    out->shadow = ok;
    out->sox = o.x; out->soy = o.y; out->soz = o.z;
    out->sdx = sd.x; out->sdy = sd.y; out->sdz = sd.z;
    out->stmax = select((float8)(0.9999f), (float8)(INFINITY), infinite);
    out->lr = L.x; out->lg = L.y; out->lb = L.z;

    /* bsdf_sample_diffuse, the side test, Russian roulette */
    uint8 key = vload8(0, in->key), rev = vload8(0, in->rev), bounce = vload8(0, in->bounce);
    float8 bu, bv, urr;
    w_rng_pair(key, rev, bounce, DIM_BSDF_U, &bu, &bv);
    w_rng_pair(key, rev, bounce, DIM_ROULETTE, &urr, 0);
    vec3x8 v_local = w_sample_cosine_hemisphere(bu, bv);
    vec3x8 wo = w_to_world_onb(v_local, ng_face);
    float8 pdf = v_local.z * K_INV_PI;
    float8 side = w3_dot(wo, ng_face);
    int8 cont = ~(side == 0.0f) & ~(side < 0.0f);
    out->advance = cont;
    vec3x8 thr = w3_mul(thr0, albedo);
    int8 rr = vload8(0, in->rr);
    float8 q = w_fmin(w3_max_comp(thr) * LANE_LOAD(bsplit), 0.95f);
    cont &= ~rr | (urr < q);
    thr = w3_select(thr, w3_scale(thr, 1.0f / q), rr);
    cont &= w3_max_comp(thr) > 0.0f;
    out->cont = cont;
    out->tr = thr.x; out->tg = thr.y; out->tb = thr.z;
    out->pdf = pdf;
    out->ox = o.x; out->oy = o.y; out->oz = o.z;
    out->dx = wo.x; out->dy = wo.y; out->dz = wo.z;
}

/* Writes lane l's results where shade_path would have; returns its SHADE_* bits (a lane
 * of shade_lanes_fast always scatters). */
KFN_INLINE uint lane_scatter(const LaneResults *r, uint l, GLOBAL Ray *ray, GLOBAL PathState *ps,
                             GLOBAL Ray *shadow_ray)
{
    uint result = SHADE_SCATTERED;
    if (r->shadow[l]) {
        ps->shadow_L = v3(r->lr[l], r->lg[l], r->lb[l]);
        shadow_ray->o = v3(r->sox[l], r->soy[l], r->soz[l]);
        shadow_ray->d = v3(r->sdx[l], r->sdy[l], r->sdz[l]);
        shadow_ray->tmin = 0.0f;
        shadow_ray->tmax = r->stmax[l];
        result |= SHADE_SHADOW;
    }
    if (!r->advance[l]) return result;
    ps->bounce = ps->bounce + 1u;
    if (!r->cont[l]) return result;
    ps->throughput = v3(r->tr[l], r->tg[l], r->tb[l]);
    ps->bsdf_pdf = r->pdf[l];
    ps->flags = 0u;
    ray->o = v3(r->ox[l], r->oy[l], r->oz[l]);
    ray->d = v3(r->dx[l], r->dy[l], r->dz[l]);
    ray->tmin = 0.0f;
    ray->tmax = INFINITY;
    return result | SHADE_CONTINUE;
}

/* shade_path for a lane that shade_lanes_fast does not take, in a scene and with
 * settings that kernel_lanes_scene and kernel_lanes_params (host/device/
 * kernel_features.c) accept: one whose path escaped, hit a lamp (a pure emitter, which
 * reflects nothing) or reached its last bounce on a surface. Each of these ends the
 * path, with shade_path's background or emission. Every other case, which would need
 * all of shade_path, is kept out of k_path_lanes on the host: a diffuse material that
 * emits, a light other than a triangle lamp, another material or primitive, shading
 * normals, or another sampler or setting. So shade_path is not compiled into
 * k_path_lanes, whose cold build it made a fifth longer (bench/RESULTS.md). */
KFN_INLINE uint shade_lane_end(const SceneView *sc, Ray r, Hit hit, GLOBAL PathState *ps)
{
    /* a later branch of a split first hit adds no emission (shade_path); none comes
     * here, since only a hit that scatters is split, but the rule is kept */
    if (ps->bounce == 0u && ps->branch != 0u) return 0u;
    if (hit.prim == NO_INDEX) {
        shade_escape(sc, r, ps);
        return 0u;
    }
    Surface s = surface_at(sc, r, hit);
    shade_emission(sc, r, s, sc->materials[s.material], ps);
    return 0u;
}

/* One bounce of the live lanes (bits of `live`) of paths path[0..7]: shade_path's
 * results, the common case eight at a time. */
KFN_CALL_CL void shade_lanes(const SceneView *sc, uint live, const uint *path, const Hit *hits, GLOBAL Ray *rays,
                             GLOBAL PathState *paths, GLOBAL Ray *shadow_rays, uint *result)
{
    GLOBAL const RenderParams *p = sc->params;
    uint fast = 0u;
    LaneInputs in;
    if (p->sampler == SAMPLER_SOBOL && p->mis_mode == MIS_BOTH && p->shadows && p->n_lights > 0u) {
        /* lanes not shaded here compute on zeros, harmlessly */
        float8 zero = 0.0f;
        for (uint k = 0; k < sizeof in / sizeof(float8); k++) vstore8(zero, k, (float *)&in);
        for (uint l = 0; l < PATH_LANES; l++)
            if ((live & (1u << l)) && lane_surface(sc, &rays[path[l]], hits[l], &paths[path[l]], &in, l))
                fast |= 1u << l;
    }
    if (fast) {
        /* the light pair of every lane at once (shade_light_sample), then each lane's light */
        float8 lu, lv;
        w_rng_pair(vload8(0, in.key), vload8(0, in.rev), vload8(0, in.bounce), DIM_LIGHT_U, &lu, &lv);
        vstore8(lv, 0, in.lv);
        for (uint l = 0; l < PATH_LANES; l++)
            if ((fast & (1u << l)) && !lane_light(sc, lu[l], &in, l)) fast &= ~(1u << l);
    }
    for (uint l = 0; l < PATH_LANES; l++) {
        uint i = path[l];
        if ((live & ~fast) & (1u << l)) result[l] = shade_lane_end(sc, rays[i], hits[l], &paths[i]);
    }
    if (!fast) return;
    LaneResults r;
    shade_lanes_fast(&in, &r);
    for (uint l = 0; l < PATH_LANES; l++) {
        if (!(fast & (1u << l))) continue;
        uint i = path[l];
        result[l] = lane_scatter(&r, l, &rays[i], &paths[i], &shadow_rays[i]);
    }
}

#endif /* CLPT_SHADE_LANES_H */
