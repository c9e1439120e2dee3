/* crop.h — the window of the image a render covers: pbrt's Film "cropwindow" (fractions
 * of the image) and "pixelbounds" (pixels), clpt's --crop and --pixel-bounds. The film
 * then holds the window alone, and its pixels are the whole render's (RenderParams,
 * crop_left ...). */
#ifndef CLPT_CROP_H
#define CLPT_CROP_H

#include "types.h"

enum CropKind {
    CROP_NONE = 0,
    CROP_FRACTIONS = 1,   /* x0 x1 y0 y1 in [0, 1], x0 < x1, y0 < y1: pbrt's cropwindow */
    CROP_PIXELS = 2       /* columns [x0, x1), rows [y0, y1), row 0 at the top */
};

typedef struct {
    uint kind;             /* enum CropKind */
    double x0, x1, y0, y1;
} SceneCrop;

/* The window in pixels: columns [x0, x0 + width), rows [y0, y0 + height). */
typedef struct {
    uint x0, y0, width, height;
} CropWindow;

/* The window c selects of a width x height image (the whole image for CROP_NONE). A
 * fraction f becomes column ceil(f * width), as pbrt-v4 rounds it, so that abutting
 * windows share no pixel and miss none. 0 when the window holds no pixel or goes past
 * the image (the caller says which flag or file asked for it). */
int crop_window(const SceneCrop *c, uint width, uint height, CropWindow *out);

#endif /* CLPT_CROP_H */
