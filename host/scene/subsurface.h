/*
 * subsurface.h — subsurface scattering by random walk (docs/subsurface.md): the interior
 * medium of a principled material with `subsurface` > 0, made from a colour and a mean
 * free path (or given coefficients), which the kernels walk as a MEDIUM_WALK medium
 * bounded by the material's surface.
 */
#ifndef CLPT_SCENE_SUBSURFACE_H
#define CLPT_SCENE_SUBSURFACE_H

#include "scene/scene.h"

/* The single-scattering albedo a homogeneous, isotropic half-space needs to reflect a
 * share `color` (in [0, 1]) of the light it receives, all bounces together: Christensen
 * and Burley's fit (2015, sec. 5). Monotone, 0 at 0 and 1 at 1. */
float subsurface_single_albedo(float color);

/* The interior's coefficients per unit of scene length from the colour (the
 * multiple-scattering albedo, each channel in [0, 1]) and the mean free path mfp (each
 * channel > 0, already times the material's scale): sigma_t = 1 / mfp, sigma_s =
 * alpha sigma_t with alpha = subsurface_single_albedo(color), sigma_a the rest. */
void subsurface_coefficients(vec3 color, vec3 mfp, vec3 *sigma_a, vec3 *sigma_s);

/* Gives principled material *m (not yet added to s) subsurface weight `weight` in
 * (0, 1] over an interior medium of sigma_a, sigma_s (finite, >= 0) and
 * Henyey-Greenstein g: adds that medium to s (MEDIUM_WALK, named after the material)
 * and makes it m's interior; the exterior is the background's medium, set when the
 * render is prepared (scene_prepare_media). Fails only when memory runs out. */
Status scene_add_subsurface(Scene *s, Material *m, const char *material_name, float weight, vec3 sigma_a,
                            vec3 sigma_s, float g, Error *err);

/* Whether some medium is a subsurface walk's (RenderParams.has_media's HAS_MEDIA_WALK). */
int scene_has_subsurface(const Scene *s);

#endif /* CLPT_SCENE_SUBSURFACE_H */
