/* crop.c — see crop.h. */
#include "scene/crop.h"

#include <math.h>

int crop_window(const SceneCrop *c, uint width, uint height, CropWindow *out)
{
    double x0 = 0.0, x1 = width, y0 = 0.0, y1 = height;
    if (c->kind == CROP_FRACTIONS) {
        x0 = ceil(c->x0 * width);
        x1 = ceil(c->x1 * width);
        y0 = ceil(c->y0 * height);
        y1 = ceil(c->y1 * height);
    } else if (c->kind == CROP_PIXELS) {
        x0 = c->x0, x1 = c->x1, y0 = c->y0, y1 = c->y1;
    }
    /* written so that a NaN fails every test */
    if (!(x0 >= 0.0 && x0 < x1 && x1 <= width && y0 >= 0.0 && y0 < y1 && y1 <= height)) return 0;
    out->x0 = (uint)x0;
    out->y0 = (uint)y0;
    out->width = (uint)(x1 - x0);
    out->height = (uint)(y1 - y0);
    return 1;
}
