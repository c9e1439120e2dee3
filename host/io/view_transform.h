/*
 * view_transform.h — how linear radiance becomes a picture on a display: an exposure
 * (a scale of 2^EV) and a view transform, from scene-linear Rec.709 to display-linear
 * Rec.709 in [0, 1], which the 8-bit (and 16-bit) encoders then give the sRGB curve (or
 * none, --gamma none). Float outputs (PFM, EXR, HDR) keep the radiance as it is.
 *
 *  VIEW_STANDARD  the values as they are, clipped at 1 by the encoder (clpt's images
 *                 before views existed, and still the default, bit for bit);
 *  VIEW_AGX       AgX, the default view of Blender 4, from its published description:
 *                 Eary Chow's AgX_LUT_Gen (AgXBaseRec2020.py, the script that made
 *                 Blender 4.0's AgX Base LUT) with Troy Sobotka's SB2383 inset/outset
 *                 matrices and Jed Smith's tunable sigmoid; see view_transform.c;
 *  VIEW_FILMIC    John Hable's filmic curve ("Filmic Tonemapping Operators",
 *                 filmicworlds.com, 2010; GDC 2010 "Uncharted 2: HDR Lighting"), per
 *                 channel, with his published constants, exposure bias 2 and white 11.2.
 *
 * Every input maps to a value in [0, 1]: NaN counts as 0, negative values as AgX's lower
 * guard rail or the standard and filmic clip make them, +inf and huge values white.
 */
#ifndef CLPT_VIEW_TRANSFORM_H
#define CLPT_VIEW_TRANSFORM_H

#include <stddef.h>

typedef enum { VIEW_STANDARD = 0, VIEW_AGX = 1, VIEW_FILMIC = 2 } ViewTransform;

/* What forms the picture: the view, and the exposure in stops applied before it. */
typedef struct {
    ViewTransform view;
    double exposure;
} ViewLook;

/* Whether `look` changes anything: the standard view at exposure 0 does not, and the
 * image is then written exactly as before views existed. */
int view_look_is_identity(const ViewLook *look);

/* One pixel, scene-linear Rec.709 in, display-linear Rec.709 in [0, 1] out. */
void view_pixel(const ViewLook *look, const float in[3], float out[3]);

/* n pixels of interleaved RGB in place. */
void view_apply(const ViewLook *look, float *rgb, size_t n_pixels);

/* The pieces, for the tests: AgX's sigmoid on its log2 axis (0 at -10 stops from 0.18,
 * 1 at +6.5), and Hable's curve normalised to white (before clipping). */
double view_agx_sigmoid(double x);
double view_filmic_curve(double x);

/* "standard", "agx" or "filmic". */
const char *view_name(ViewTransform v);

#endif /* CLPT_VIEW_TRANSFORM_H */
