/*
 * cube_env.h — a cube-map background made an environment light for the path tracer:
 * the six faces resampled into an equirectangular float map (kernels/light/envmap.h's
 * orientation), which then becomes the background by scene_set_envmap, so next-event
 * estimation samples it and MIS weights what BSDF-sampled rays see of it, as for a
 * `background { map ... }`. The Whitted integrator keeps the exact cube-map lookup
 * (kernels/light/background.h); only the path tracer converts (render_scene_prepare).
 */
#ifndef CLPT_CUBE_ENV_H
#define CLPT_CUBE_ENV_H

#include "base/status.h"
#include "scene/scene.h"

/* Smallest and largest height of the resampled map (its width is twice that): at 256
 * rows a map texel spans 0.7 degrees, so the edges between faces of a few texels stay
 * sharp; 1024 rows (25 MB of floats) bound the memory for large faces. */
#define CUBE_ENV_MIN_HEIGHT 256u
#define CUBE_ENV_MAX_HEIGHT 1024u

/* Height of the map for faces at most `face` texels on a side: 2 face (a face spans a
 * quarter of the width and half the height at the horizon), within the bounds above. */
uint cube_env_height(uint face);

/* Replaces the cube-map background of s (bg_type BG_CUBEMAP) with an environment map
 * of 2 H x H texels (H = cube_env_height of the largest face side), each the mean of
 * the cube map's own lookup (kernels/light/background.h's cubemap_lookup, so the faces' (u,
 * v) and filtering are exactly the Whitted integrator's) in the directions of a 3 x 3
 * grid of points in the texel, appended as a TEX_FLOAT texture; the background becomes
 * BG_MAP with intensity 1 and rotation 0. Fails only when memory runs out or the
 * texels would pass the texture buffer's limit (scene_add_texels). */
Status cube_env_convert(Scene *s, Error *err);

#endif /* CLPT_CUBE_ENV_H */
