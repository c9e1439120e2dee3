/*
 * media.h — participating media in the host's scene (kernels/medium/, docs/media.md):
 * the named media, the materials of shapes that bound them, the boundary that is no
 * surface (`material none`), and their resolution when a render is prepared.
 *
 * A shape bounds media through its material: the kernels read a surface's interior and
 * exterior medium from Material.medium_in/medium_out, so a shape given media gets a copy
 * of its material carrying them (one copy per material and pair of media, shared by
 * every shape that asks for the same). The copies keep their original's name, so
 * `--set material.NAME.*` reaches them too, and scene_prepare_media copies each
 * original over its copies again before a render.
 */
#ifndef CLPT_SCENE_MEDIA_H
#define CLPT_SCENE_MEDIA_H

#include "scene/scene.h"
#include "scene/transform.h"

/* A homogeneous medium: absorption and scattering per unit of scene length (already
 * scaled), Henyey-Greenstein g in (-1, 1) (|g| < 1e-3 stored as 0, types.h). */
Medium medium_homogeneous(vec3 sigma_a, vec3 sigma_s, float g);

/* The most cells per axis of a grid's majorant grid (pbrt-v4's MajorantGrid is 16^3). */
#define GRID_MAJORANT_RES 16u

/* Adds a density grid to s->grids for a MEDIUM_GRID medium (*grid its index): nx ny nz
 * densities (x fastest, each finite and >= 0: the reader checks), at the cell centres
 * of the box [lo, hi] of the medium's space, which to_world places in the scene (an
 * invertible affine transform). Computes its majorant grid. Fails only when memory
 * runs out or the grids grow past 2^32 floats. */
Status scene_add_grid(Scene *s, const float *density, uint nx, uint ny, uint nz, vec3 lo, vec3 hi,
                      const Transform *to_world, uint *grid, Error *err);

/* A grid medium: coefficients per unit of density, HG g, its grid in s->grids. */
Medium medium_grid(vec3 sigma_a, vec3 sigma_s, float g, uint grid);

/* Medium m emitting radiance `le` (each channel finite and >= 0: the reader checks):
 * a stretch ds of it adds sigma_a Le ds (docs/media.md, "Emission"). */
Medium medium_with_emission(Medium m, vec3 le);

/* Gives grid `grid` (scene_add_grid) a per-cell emission scale, nx ny nz values of its
 * size (finite, >= 0: the reader checks), interpolated as its density: pbrt-v4's
 * "Lescale" grid. Fails only when memory runs out or the grids pass 2^32 floats. */
Status scene_grid_set_emission(Scene *s, uint grid, const float *scale, Error *err);
/* Whether a grid's emission fits single precision: the kernels multiply a lookup of the
 * density by one of the n emission scales, and sigma_a times Le (sa_le, its largest
 * channel, times `factor`: a blackbody's brightest for a temperature grid, else 1) by
 * that over the majorant, which the density cancels (kernels/medium/grid.h,
 * grid_emitted). So the largest density times the largest scale, and sa_le times the
 * largest scale, must each stay below the largest float. *top: the largest scale's
 * index, for the readers' messages. */
int grid_emission_fits(const float *density, const float *scale, size_t n, double sa_le, double factor,
                       size_t *top);

/* How a temperature grid's values become kelvin: T = (value - offset) * scale (pbrt-v4's
 * "temperatureoffset" and "temperaturescale"); where T <= GRID_TEMPERATURE_CUTOFF
 * (types.h) nothing glows (pbrt-v4's fixed 100 K). */
typedef struct {
    double offset, scale;   /* finite; scale >= 0 */
} GridTemperature;

/* Temperatures above this are taken as this: beyond it the table's steps would grow
 * past 2 400 K and the glow is no fire's (pbrt-v4 takes any value). */
#define GRID_TEMPERATURE_MAX 1e7

/* Gives grid `grid` a temperature per cell from nx ny nz values of its size (finite,
 * >= 0: the reader checks), made kelvin as `how` says, and the blackbody table of its
 * hottest (types.h, GridBlackbody: pbrt-v4's BlackbodySpectrum(T), peak 1, as linear
 * sRGB, scene/blackbody.h). The kernels interpolate the temperature as the density and
 * take its colour; the medium's emission multiplies it (pbrt-v4's Lescale). Fails only
 * when memory runs out or the grids pass 2^32 floats. */
Status scene_grid_set_temperature(Scene *s, uint grid, const float *temperature, GridTemperature how, Error *err);

/* Adds medium m named `name` (the caller checks that the name is new). Fails only when
 * memory runs out. */
Status scene_add_medium(Scene *s, const char *name, Medium m, uint *index, Error *err);

/* The index of the medium named name[0, len), or NO_INDEX. */
uint scene_find_medium(const Scene *s, const char *name, size_t len);

/* A material that is no surface, only a boundary between media (MAT_INTERFACE). */
Material material_interface(void);

/* The material of surfaces that are only a boundary (MAT_INTERFACE: `material none`,
 * pbrt's "interface"), added on first use. Fails only when memory runs out. */
Status scene_interface_material(Scene *s, uint *index, Error *err);

/* The material a shape of material `material` gets when it bounds medium `in` inside
 * and `out` outside (each 0 vacuum, 1 + a medium index, or SCENE_MEDIUM_UNSET: the
 * background's): `material` itself when both are unset (the shape is no boundary of
 * its own), else its copy bound to them. Fails only when memory runs out. */
Status scene_bind_media(Scene *s, uint material, uint in, uint out, uint *bound, Error *err);

/* 0 for vacuum or 1 + a medium index, with SCENE_MEDIUM_UNSET read as the background's. */
uint scene_medium_resolve(const Scene *s, uint ref);

/* Whether a path can meet a medium or a boundary: some medium is in use or some
 * material is MAT_INTERFACE (RenderParams.has_media). */
int scene_has_media(const Scene *s);

/* Before a render: each bound material made again from its original, with the
 * background's medium put where a side was left unset. */
void scene_prepare_media(Scene *s);

#endif /* CLPT_SCENE_MEDIA_H */
