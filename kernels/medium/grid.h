/*
 * grid.h — heterogeneous media: a density grid (GridMedium, types.h) times the
 * medium's per-density coefficients. Free-flight distances by delta tracking and
 * shadow-ray transmittance by ratio tracking, both against a piecewise-constant
 * majorant that a 3D DDA walks cell by cell, so that empty space costs one step per
 * cell and no collision. docs/media.md derives the estimators.
 *
 * Delta tracking (Woodcock et al. 1965) with a majorant: tentative collisions are
 * drawn from the exponential of the majorant sigma_bar; at each, the real extinction
 * mu_t(x) decides between a real collision and a null one. Chromatic media use
 * spectral tracking (Kutz, Habel, Li, Novák, "Spectral and decomposition tracking for
 * rendering heterogeneous volumes", SIGGRAPH 2017): one majorant for all channels (the
 * largest sigma_t times the cell's density), the real collision chosen with the
 * probability P = sum_c q_c mu_t,c / sigma_bar, q the path's throughput shares (its
 * history, as Kutz's "history-aware" variant), and every channel weighted by the
 * ratio of its own event density to that probability: mu_s,c / sum_c q_c mu_t,c at a
 * real collision (the stop's scattering weight; absorption is not sampled, as for the
 * homogeneous media), (sigma_bar - mu_t,c) / (sigma_bar - sum_c q_c mu_t,c) at a null
 * one. Each channel's estimate is unbiased whatever the probabilities; with equal
 * channels the weights are the albedo and 1, plain delta tracking.
 *
 * Ratio tracking (Novák, Selle, Jarosz, "Residual ratio tracking for estimating
 * attenuation in participating media", SIGGRAPH Asia 2014, sec. 3): the same tentative
 * collisions, each multiplying the transmittance by 1 - mu_t,c / sigma_bar, with
 * Russian roulette once it falls below 0.05 (as pbrt-v4). Residual ratio tracking (the
 * same paper, sec. 4), for every transmittance that carries no emission: per majorant
 * cell a control extinction mu_c = sigma_t d_min (the cell's minorant) whose
 * transmittance exp(-mu_c len) is exact, and ratio tracking of the residual mu_t - mu_c
 * only, against the residual majorant sigma_t,max (d_max - d_min); a cell of constant
 * density costs no collision and adds no noise.
 *
 * Random numbers: the first distance of a flight is the sampler's DIM_MEDIUM (so the
 * first, most important, collision is stratified as the homogeneous media's are);
 * every further number comes from a counter-based hash stream of the path's key, its
 * sample, its bounce and a tag (grid_rng_seed), so the same bits on every device.
 */
#ifndef CLPT_GRID_H
#define CLPT_GRID_H

#include "util/kmath.h"
#include "types.h"
#include "sample/rng.h"
#include "scene_view.h"
#include "medium/medium.h"

/* The most tentative collisions one flight or shadow stretch takes: a hang guard for
 * absurd optical depths (a majorant's optical depth of tens of thousands along one
 * ray is opaque long before). A flight that reaches it ends the path, a shadow ray
 * counts as blocked. */
#define GRID_MAX_STEPS 65536u

/* Where a flight through a grid ended (grid_track). */
enum GridFlight { GRID_PASSED = 0, GRID_STOPPED = 1, GRID_ENDED = 2 };

/* Stream tags: a flight's numbers and a shadow ray's differ at the same bounce. */
#define GRID_TAG_FLIGHT 0x5f3759dfu
#define GRID_TAG_SHADOW 0x2545f491u

KFN uint grid_rng_seed(RngKey k, uint bounce, uint tag)
{
    return rng_hash(k.key ^ rng_hash(k.sample * 0x9e3779b9u ^ rng_hash(bounce * (uint)RNG_DIMS_PER_BOUNCE + tag)));
}

/* The stream's next uniform in [0, 1). */
KFN float grid_rng_next(uint *state)
{
    *state = *state + 0x9e3779b9u;
    return rng_to_float(rng_hash(*state));
}

/* A distance of the exponential of rate sigma > 0. */
KFN float grid_exp_step(float sigma, float u)
{
    return -k_log2(1.0f - u) * 0.693147181f / sigma;
}

KFN vec3 grid_to_unit(const GridMedium *g, vec3 p)
{
    return v3(g->to_grid[0] * p.x + g->to_grid[1] * p.y + g->to_grid[2] * p.z + g->to_grid[3],
              g->to_grid[4] * p.x + g->to_grid[5] * p.y + g->to_grid[6] * p.z + g->to_grid[7],
              g->to_grid[8] * p.x + g->to_grid[9] * p.y + g->to_grid[10] * p.z + g->to_grid[11]);
}

KFN vec3 grid_dir_to_unit(const GridMedium *g, vec3 d)
{
    return v3(g->to_grid[0] * d.x + g->to_grid[1] * d.y + g->to_grid[2] * d.z,
              g->to_grid[4] * d.x + g->to_grid[5] * d.y + g->to_grid[6] * d.z,
              g->to_grid[8] * d.x + g->to_grid[9] * d.y + g->to_grid[10] * d.z);
}

/* Along one axis of n samples at cell centres: the lower sample's index, the upper
 * one's and the weight of the upper, for unit coordinate q (clamped to the outermost
 * centres). */
KFN void grid_axis(float q, uint n, uint *i0, uint *i1, float *f)
{
    float x = k_clamp(q * (float)n - 0.5f, 0.0f, (float)(n - 1u));
    uint i = (uint)x;
    if (i > n - 1u) i = n - 1u;
    *i0 = i;
    *i1 = i + 1u < n ? i + 1u : i;
    *f = x - (float)i;
}

KFN float grid_lerp(float a, float b, float f) { return a + (b - a) * f; }

/* A grid of g's size stored in grid_data from `at` (the density, or the emission
 * scale) at unit-cube point q: trilinear between the 8 nearest cell centres. */
KFN float grid_lookup(const SceneView *sc, const GridMedium *g, uint at, vec3 q)
{
    uint x0, x1, y0, y1, z0, z1;
    float fx, fy, fz;
    grid_axis(q.x, g->nx, &x0, &x1, &fx);
    grid_axis(q.y, g->ny, &y0, &y1, &fy);
    grid_axis(q.z, g->nz, &z0, &z1, &fz);
    GLOBAL const float *v = sc->grid_data + at;
    uint nx = g->nx, nxy = g->nx * g->ny;
    float c00 = grid_lerp(v[z0 * nxy + y0 * nx + x0], v[z0 * nxy + y0 * nx + x1], fx);
    float c10 = grid_lerp(v[z0 * nxy + y1 * nx + x0], v[z0 * nxy + y1 * nx + x1], fx);
    float c01 = grid_lerp(v[z1 * nxy + y0 * nx + x0], v[z1 * nxy + y0 * nx + x1], fx);
    float c11 = grid_lerp(v[z1 * nxy + y1 * nx + x0], v[z1 * nxy + y1 * nx + x1], fx);
    return grid_lerp(grid_lerp(c00, c10, fy), grid_lerp(c01, c11, fy), fz);
}

KFN float grid_density(const SceneView *sc, const GridMedium *g, vec3 q)
{
    return grid_lookup(sc, g, g->density_at, q);
}

/* The blackbody colour of a temperature grid's `kelvin` (an interpolated cell value):
 * its table (types.h, GridBlackbody) linear between steps; 0 0 0 at or below the
 * cutoff. Interpolating the temperature first and taking its colour after is pbrt-v4's
 * order (GridMedium::SamplePoint), which a baked colour per cell would not keep: the
 * colour is convex in T. */
KFN vec3 grid_blackbody(const SceneView *sc, const GridMedium *g, float kelvin)
{
    if (!(kelvin > GRID_TEMPERATURE_CUTOFF)) return v3s(0.0f);
    GLOBAL const float *head = sc->grid_data + g->temperature_at + g->nx * g->ny * g->nz;
    float x = k_fmin(kelvin * head[0], (float)(GRID_BLACKBODY_STEPS - 1u));
    uint i = (uint)x;
    if (i > GRID_BLACKBODY_STEPS - 2u) i = GRID_BLACKBODY_STEPS - 2u;
    float f = x - (float)i;
    GLOBAL const float *lo = head + 1u + 3u * i;
    return v3(grid_lerp(lo[0], lo[3], f), grid_lerp(lo[1], lo[4], f), grid_lerp(lo[2], lo[5], f));
}

/* What a tentative collision at unit-cube point q of density dens adds to the path's
 * emitted radiance, per unit of its weight w: w sigma_a(q) Le(q) / sigma_bar, where
 * sigma_a(q) = dens sigma_a and Le(q) the medium's emission times the cell's scale
 * (pbrt-v4's GridMedium: Le_spec times its "Lescale" grid) and, when the grid has a
 * temperature grid, the blackbody colour of its temperature at q (pbrt-v4's
 * BlackbodySpectrum(T(q)); docs/media.md, "Blackbody emission"). Collisions arrive at rate
 * sigma_bar along the ray and w estimates the transmittance up to q, so the sum over
 * a flight estimates the emission integral int T(t) sigma_a(t) Le(t) dt without bias
 * (Pharr, Jakob, Humphreys, PBR 4th ed., sec. 14.2.2: pbrt-v4's VolPathIntegrator
 * adds beta sigma_a Le / sigma_maj at every tentative collision). */
KFN vec3 grid_emitted(const SceneView *sc, const GridMedium *g, Medium md, vec3 q, float dens, vec3 w, float bar)
{
    float scale = g->emission_at != 0u ? grid_lookup(sc, g, g->emission_at, q) : 1.0f;
    vec3 e = md.emission;
    if (g->temperature_at != 0u) e = v3_mul(e, grid_blackbody(sc, g, grid_lookup(sc, g, g->temperature_at, q)));
    vec3 le = v3_scale(v3_mul(md.sigma_a, e), dens * scale / bar);
    return v3_mul(w, le);
}

/* A 3D DDA over the majorant grid (Amanatides and Woo, "A fast voxel traversal
 * algorithm", Eurographics 1987), in the ray's distance t: each step gives one cell
 * and the stretch [t, t_end of the cell) the ray spends in it. */
typedef struct {
    float t, t_end;
    int cell[3], step[3], stop[3];
    float next[3], delta[3];
} GridWalk;

/* Starts the walk of unit-space ray o + t d over t in [t_lo, t_hi], clipped to the
 * unit cube; 0 when the ray misses the box within that interval. */
KFN int grid_walk_begin(const GridMedium *g, vec3 o, vec3 d, float t_lo, float t_hi, GridWalk *w)
{
    float t0 = t_lo, t1 = t_hi;
    uint res[3] = { g->mx, g->my, g->mz };
    for (int a = 0; a < 3; a++) {
        float oa = v3_get(o, a), da = v3_get(d, a);
        if (da == 0.0f) {
            if (oa < 0.0f || oa > 1.0f) return 0;
            continue;
        }
        float ta = (0.0f - oa) / da, tb = (1.0f - oa) / da;
        t0 = k_fmax(t0, k_fmin(ta, tb));
        t1 = k_fmin(t1, k_fmax(ta, tb));
    }
    if (!(t0 < t1)) return 0;
    w->t = t0;
    w->t_end = t1;
    for (int a = 0; a < 3; a++) {
        float oa = v3_get(o, a), da = v3_get(d, a);
        float m = (float)res[a];
        float pa = oa + da * t0;
        int c = (int)k_clamp(pa * m, 0.0f, m - 1.0f);
        w->cell[a] = c;
        if (da > 0.0f) {
            w->next[a] = t0 + ((float)(c + 1) / m - pa) / da;
            w->delta[a] = 1.0f / (m * da);
            w->step[a] = 1;
            w->stop[a] = (int)res[a];
        } else if (da < 0.0f) {
            w->next[a] = t0 + ((float)c / m - pa) / da;
            w->delta[a] = -1.0f / (m * da);
            w->step[a] = -1;
            w->stop[a] = -1;
        } else {
            w->next[a] = k_as_float(0x7f800000u);
            w->delta[a] = 0.0f;
            w->step[a] = 0;
            w->stop[a] = -1;
        }
    }
    return 1;
}

/* The next cell: its index in the majorant grid and the stretch [*lo, *hi) of it; 0
 * when the walk is over. */
KFN int grid_walk_next(const GridMedium *g, GridWalk *w, float *lo, float *hi, uint *cell)
{
    if (!(w->t < w->t_end)) return 0;
    int a = w->next[0] < w->next[1] ? (w->next[0] < w->next[2] ? 0 : 2) : (w->next[1] < w->next[2] ? 1 : 2);
    *lo = w->t;
    *hi = k_fmin(w->next[a], w->t_end);
    *cell = ((uint)w->cell[2] * g->my + (uint)w->cell[1]) * g->mx + (uint)w->cell[0];
    w->t = *hi;
    w->cell[a] += w->step[a];
    w->next[a] += w->delta[a];
    if (w->cell[a] == w->stop[a]) w->t = w->t_end;
    return 1;
}

/* What every flight through a grid medium starts with (grid_track and both
 * transmittance estimators): the medium's grid, sigma_t and its largest channel (the
 * majorant's scale) and the world ray x + t d in the grid's unit space. */
typedef struct {
    GridMedium g;
    vec3 sig_t;
    float sig_max;
    vec3 o, du;                  /* origin and direction in unit space */
} GridFlight;

/* Sets *fl up and begins the walk *w over t in [0, dist); 0 when there is nothing to
 * walk (a medium that neither absorbs nor scatters, or a ray that misses the grid's
 * box before dist). Inlined as the three set-ups it replaces were. The walk stays out
 * of GridFlight: with it inside (its address goes to grid_walk_begin, out of line),
 * gcc stopped inlining grid_rng_next into the scalar device's grid loops. */
KFN_INLINE int grid_flight_begin(const SceneView *sc, Medium md, vec3 x, vec3 d, float dist, GridFlight *fl,
                                 GridWalk *w)
{
    fl->g = sc->grids[md.grid];
    fl->sig_t = v3_add(md.sigma_a, md.sigma_s);
    fl->sig_max = v3_max_comp(fl->sig_t);
    fl->o = grid_to_unit(&fl->g, x);
    fl->du = grid_dir_to_unit(&fl->g, d);
    return fl->sig_max > 0.0f && grid_walk_begin(&fl->g, fl->o, fl->du, 0.0f, dist, w);
}

/* Delta (spectral) tracking of the world ray x + t d (d unit length) for t in
 * [0, dist) through grid medium md: GRID_STOPPED with the real collision's distance in
 * *t_stop, GRID_PASSED when it flies past dist, GRID_ENDED when the weight vanished or
 * the walk gave up. *thr takes every null collision's weight and the stop's. u_first is
 * the first tentative collision's number, *rng the stream of the others. An emissive
 * medium adds each tentative collision's emission (grid_emitted, with the weight
 * before that collision's) to *emitted. */
KFN int grid_track(const SceneView *sc, Medium md, vec3 x, vec3 d, float dist, vec3 *thr, float u_first,
                   uint *rng, float *t_stop, vec3 *emitted)
{
    GridFlight fl;
    GridWalk w;
    if (!grid_flight_begin(sc, md, x, d, dist, &fl, &w)) return GRID_PASSED;
    float lo, hi;
    uint cell, steps = 0u;
    int first = 1;
    while (grid_walk_next(&fl.g, &w, &lo, &hi, &cell)) {
        float bar = sc->grid_data[fl.g.majorant_at + cell] * fl.sig_max;
        if (!(bar > 0.0f)) continue;
        float t = lo;
        for (;;) {
            if (++steps > GRID_MAX_STEPS) return GRID_ENDED;
            float u = first ? u_first : grid_rng_next(rng);
            first = 0;
            t = t + grid_exp_step(bar, u);
            if (!(t < hi)) break;   /* memoryless: the next cell starts afresh at hi */
            vec3 p = v3_madd(fl.o, fl.du, t);
            float dens = grid_density(sc, &fl.g, p);
            if (md.flags & MEDIUM_EMISSIVE)
                *emitted = v3_add(*emitted, grid_emitted(sc, &fl.g, md, p, dens, *thr, bar));
            vec3 mu_t = v3_scale(fl.sig_t, dens);
            vec3 q = medium_channel_pdf(*thr);
            float real = v3_dot(q, mu_t);
            if (grid_rng_next(rng) * bar < real) {
                *thr = v3_scale(v3_mul(*thr, v3_scale(md.sigma_s, dens)), 1.0f / real);
                *t_stop = t;
                return GRID_STOPPED;
            }
            /* the majorant bounds the density up to rounding at the cells' faces: a
             * null density below 0 is taken as 0 */
            vec3 mu_n = v3(k_fmax(bar - mu_t.x, 0.0f), k_fmax(bar - mu_t.y, 0.0f), k_fmax(bar - mu_t.z, 0.0f));
            *thr = v3_scale(v3_mul(*thr, mu_n), 1.0f / (bar - real));
            if (!(v3_max_comp(*thr) > 0.0f)) return GRID_ENDED;
        }
    }
    return GRID_PASSED;
}

/* An optical depth past which a transmittance estimate may be below the roulette's
 * level (exp(-3) = 0.0498 < 0.05): residual tracking takes its controls' exponentials
 * there, not per cell. */
#define GRID_TAU_ROULETTE 3.0f

/* Russian roulette on a transmittance estimate that has fallen below 0.05 in every
 * channel: kept with probability 1/4 and then 4 times as large (as pbrt-v4), so that
 * an opaque stretch stops early without bias. 0 when the estimate ends. */
KFN int grid_tr_roulette(vec3 *tr, uint *rng)
{
    float m = v3_max_comp(*tr);
    if (m < 0.05f) {
        if (!(m > 0.0f) || grid_rng_next(rng) < 0.75f) return 0;
        *tr = v3_scale(*tr, 4.0f);
    }
    return 1;
}

/* Ratio tracking's estimate of the transmittance of emissive grid medium md along the
 * world ray x + t d (d unit length), t in [0, dist); numbers from *rng. Each tentative
 * collision's emission is added to *emitted, weighted by the transmittance estimated up
 * to there: the collisions must come at the full majorant's rate for that sum to
 * estimate the emission integral, which is why emissive flights keep plain ratio
 * tracking (residual tracking finds no collision in a cell of constant density). */
KFN vec3 grid_transmittance_ratio(const SceneView *sc, Medium md, vec3 x, vec3 d, float dist, uint *rng,
                                  vec3 *emitted)
{
    GridFlight fl;
    GridWalk w;
    vec3 tr = v3s(1.0f);
    if (!grid_flight_begin(sc, md, x, d, dist, &fl, &w)) return tr;
    float lo, hi;
    uint cell, steps = 0u;
    while (grid_walk_next(&fl.g, &w, &lo, &hi, &cell)) {
        float bar = sc->grid_data[fl.g.majorant_at + cell] * fl.sig_max;
        if (!(bar > 0.0f)) continue;
        float inv = 1.0f / bar;
        float t = lo;
        for (;;) {
            if (++steps > GRID_MAX_STEPS) return v3s(0.0f);
            t = t + grid_exp_step(bar, grid_rng_next(rng));
            if (!(t < hi)) break;
            vec3 p = v3_madd(fl.o, fl.du, t);
            float dens = grid_density(sc, &fl.g, p);
            *emitted = v3_add(*emitted, grid_emitted(sc, &fl.g, md, p, dens, tr, bar));
            vec3 mu_t = v3_scale(fl.sig_t, dens);
            tr = v3_mul(tr, v3(k_fmax(1.0f - mu_t.x * inv, 0.0f), k_fmax(1.0f - mu_t.y * inv, 0.0f),
                               k_fmax(1.0f - mu_t.z * inv, 0.0f)));
            if (!grid_tr_roulette(&tr, rng)) return v3s(0.0f);
        }
    }
    return tr;
}

/* Residual ratio tracking's estimate of the transmittance of grid medium md along the
 * world ray x + t d (d unit length), t in [0, dist); numbers from *rng (Novák, Selle,
 * Jarosz, "Residual ratio tracking for estimating attenuation in participating media",
 * SIGGRAPH Asia 2014, sec. 4). T = exp(-int mu_t) splits, for any control mu_c, into
 * exp(-int mu_c) exp(-int (mu_t - mu_c)): the first factor is exact when mu_c is
 * constant on each stretch, and ratio tracking estimates the second against a
 * majorant of the residual mu_t - mu_c. In majorant cell k the control is sigma_t
 * d_min,k and the residual majorant sigma_t,max (d_max,k - d_min,k) (types.h,
 * GridMedium.minorant_at): the residual's factors 1 - sigma_t,c (d - d_min) / that
 * majorant stay in [0, 1] in every channel, the estimate is unbiased for any control,
 * and its variance and its number of collisions shrink with the residual (none in a
 * cell of constant density, where the estimate is exact). The minorant is the
 * smallest sample the interpolation blends, so d >= d_min but for rounding at a
 * cell's face, where a factor a hair above 1 keeps the estimate unbiased still. */
KFN vec3 grid_transmittance_residual(const SceneView *sc, Medium md, vec3 x, vec3 d, float dist, uint *rng)
{
    GridFlight fl;
    GridWalk w;
    vec3 tr = v3s(1.0f);
    /* the controls' optical depth not yet in tr: its exponentials are taken where the
     * estimate needs its value (before a collision's factor and roulette, once the
     * depth alone could take it below the roulette's level, at the end), not per cell */
    vec3 tau = v3s(0.0f);
    if (!grid_flight_begin(sc, md, x, d, dist, &fl, &w)) return tr;
    float lo, hi;
    uint cell, steps = 0u;
    while (grid_walk_next(&fl.g, &w, &lo, &hi, &cell)) {
        float d_max = sc->grid_data[fl.g.majorant_at + cell];
        if (!(d_max > 0.0f)) continue;
        float d_min = sc->grid_data[fl.g.minorant_at + cell];
        if (d_min > 0.0f) {
            /* the control's transmittance over the stretch is exp(-sigma_t d_min len) */
            tau = v3_add(tau, v3_scale(v3_scale(fl.sig_t, d_min), hi - lo));
            if (v3_min_comp(tau) > GRID_TAU_ROULETTE) {
                tr = v3_mul(tr, medium_tr(tau, 1.0f));
                tau = v3s(0.0f);
                if (!grid_tr_roulette(&tr, rng)) return v3s(0.0f);
            }
        }
        float bar = (d_max - d_min) * fl.sig_max;
        if (!(bar > 0.0f)) continue;
        float inv = 1.0f / bar;
        float t = lo;
        for (;;) {
            if (++steps > GRID_MAX_STEPS) return v3s(0.0f);
            t = t + grid_exp_step(bar, grid_rng_next(rng));
            if (!(t < hi)) break;
            float res = grid_density(sc, &fl.g, v3_madd(fl.o, fl.du, t)) - d_min;
            vec3 mu_r = v3_scale(fl.sig_t, res);
            tr = v3_mul(v3_mul(tr, medium_tr(tau, 1.0f)), v3(k_fmax(1.0f - mu_r.x * inv, 0.0f),
                                                            k_fmax(1.0f - mu_r.y * inv, 0.0f),
                                                            k_fmax(1.0f - mu_r.z * inv, 0.0f)));
            tau = v3s(0.0f);
            if (!grid_tr_roulette(&tr, rng)) return v3s(0.0f);
        }
    }
    return v3_mul(tr, medium_tr(tau, 1.0f));
}

/* An estimate of the transmittance of grid medium md along the world ray x + t d (d
 * unit length), t in [0, dist); numbers from *rng. With `emitted` not NULL (a path's
 * flight, not a shadow ray) an emissive medium adds its emission along the ray to it
 * (grid_transmittance_ratio); every other transmittance is residual ratio tracking's. */
KFN vec3 grid_transmittance(const SceneView *sc, Medium md, vec3 x, vec3 d, float dist, uint *rng, vec3 *emitted)
{
    if (emitted && (md.flags & MEDIUM_EMISSIVE)) return grid_transmittance_ratio(sc, md, x, d, dist, rng, emitted);
    return grid_transmittance_residual(sc, md, x, d, dist, rng);
}

#endif /* CLPT_GRID_H */
