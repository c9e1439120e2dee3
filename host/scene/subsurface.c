/* subsurface.c — subsurface scattering's interior media (see subsurface.h). */
#include "scene/subsurface.h"

#include "scene/media.h"

#include <math.h>
#include <stdio.h>

/* P. H. Christensen, B. Burley, "Approximate reflectance profiles for efficient
 * subsurface scattering", Pixar Technical Memo 15-04 (2015), sec. 5: fitted to brute-force
 * path tracing of a semi-infinite medium, the albedo alpha that gives the total diffuse
 * reflectance A is 1 - (4.09712 + 4.20863 A - sqrt(9.59217 + 41.6808 A + 17.7126 A^2))^2.
 * Cycles' random walk inverts the colour the same way. At A = 1 the fit leaves 1 - 3e-11:
 * a white material is taken as exactly white, so that it loses nothing. */
float subsurface_single_albedo(float color)
{
    double a = color;
    if (!(a > 0.0)) return 0.0f;
    if (a >= 1.0) return 1.0f;
    double r = 4.09712 + 4.20863 * a - sqrt(9.59217 + 41.6808 * a + 17.7126 * a * a);
    double alpha = 1.0 - r * r;
    return (float)(alpha < 0.0 ? 0.0 : (alpha > 1.0 ? 1.0 : alpha));
}

static void coefficients1(float color, float mfp, float *sa, float *ss)
{
    double sigma_t = 1.0 / (double)mfp, alpha = subsurface_single_albedo(color);
    *ss = (float)(alpha * sigma_t);
    *sa = (float)((1.0 - alpha) * sigma_t);
}

void subsurface_coefficients(vec3 color, vec3 mfp, vec3 *sigma_a, vec3 *sigma_s)
{
    coefficients1(color.x, mfp.x, &sigma_a->x, &sigma_s->x);
    coefficients1(color.y, mfp.y, &sigma_a->y, &sigma_s->y);
    coefficients1(color.z, mfp.z, &sigma_a->z, &sigma_s->z);
}

Status scene_add_subsurface(Scene *s, Material *m, const char *material_name, float weight, vec3 sigma_a,
                            vec3 sigma_s, float g, Error *err)
{
    /* a name no medium statement can write (names are single words), so that the
     * scene's own media are never confused with it */
    char name[96];
    snprintf(name, sizeof name, "subsurface of '%.64s'", material_name ? material_name : "");
    Medium md = medium_homogeneous(sigma_a, sigma_s, g);
    md.flags = MEDIUM_WALK;
    uint index;
    Status st = scene_add_medium(s, name, md, &index, err);
    if (st) return st;
    m->subsurface = weight;
    m->medium_in = index + 1u;
    m->medium_out = SCENE_MEDIUM_UNSET;
    return ST_OK;
}

int scene_has_subsurface(const Scene *s)
{
    for (size_t i = 0; i < s->n_media; i++)
        if (s->media[i].flags & MEDIUM_WALK) return 1;
    return 0;
}
