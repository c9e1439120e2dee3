/*
 * view_transform.c — exposure and the standard, AgX and filmic views (view_transform.h).
 *
 * AgX, as Blender 4.0 forms it (its "AgX Base" LUT), step by step; the numbers are the
 * published parameters of that description (EaryChow/AgX_LUT_Gen, AgXBaseRec2020.py and
 * luminance_compenstation_bt2020.py; the matrices from sobotka/SB2383-Configuration-
 * Generation, generate_config.py):
 *   1. Rec.709 to Rec.2020 primaries (ITU-R BT.2087), AgX's working space;
 *   2. the lower guard rail: negative values are offset away, and the result scaled
 *      back to the luminance the offset would exceed (BT.2020 luminance weights);
 *   3. the inset matrix (SB2383 rotate [3, -1, -2], inset [0.4, 0.22, 0.13]);
 *   4. log2 encoding around middle grey 0.18, from -10 to +6.5 stops, to [0, 1]
 *      (clamped: the LUT's domain ends there, and beyond +6.5 stops its output is
 *      clipped to white);
 *   5. Jed Smith's tunable sigmoid: fulcrum at (10/16.5, 0.18^(1/2.4)), slope 2.4,
 *      toe and shoulder powers 1.5, no linear section, through (0,0) and (1,1);
 *   6. the power 2.4 back to linear;
 *   7. the hue: 40% of the per-channel hue shift kept, the rest taken back to the hue
 *      before the sigmoid (HSV hue, 0.6 before + 0.4 after);
 *   8. the outset matrix: the inverse of SB2383's rotate [0, 0, 0], inset [0.4, 0.22,
 *      0.04] matrix;
 *   9. Rec.2020 back to Rec.709, clipped to [0, 1]: the display-linear picture. The
 *      encoder gives it the sRGB curve, so middle grey 0.18 stays 0.18 on the display.
 * Blender bakes this into a 3D LUT; here it is computed per pixel, in double.
 */
#include "io/view_transform.h"

#include <math.h>

typedef double Mat3[3][3];

/* ITU-R BT.2087: linear Rec.709 to linear Rec.2020 and back (D65 both). */
static const Mat3 rec709_to_rec2020 = {
    { 0.627403895934699, 0.329283038377884, 0.043313065687417 },
    { 0.069097289358232, 0.919540395075459, 0.011362315566309 },
    { 0.016391438875150, 0.088013307877226, 0.895595253247624 },
};
static const Mat3 rec2020_to_rec709 = {
    { 1.660491002108435, -0.587641138788550, -0.072849863319885 },
    { -0.124550474521591, 1.132899897125960, -0.008349422604369 },
    { -0.018150763354905, -0.100578898008007, 1.118729661362913 },
};
/* SB2383's inset, and the matrix whose inverse is the outset (rows sum to 1: greys
 * stay grey through both). */
static const Mat3 agx_inset = {
    { 0.856627153315983, 0.0951212405381588, 0.0482516061458583 },
    { 0.137318972929847, 0.761241990602591, 0.101439036467562 },
    { 0.11189821299995, 0.0767994186031903, 0.811302368396859 },
};
static const Mat3 agx_outset_inverse = {
    { 0.899796955911611, 0.0871996192028351, 0.013003424885555 },
    { 0.11142098895748, 0.875575586156966, 0.0130034248855548 },
    { 0.11142098895748, 0.0871996192028349, 0.801379391839686 },
};
static const double rec2020_luminance[3] = { 0.2627, 0.6780, 0.0593 };

#define AGX_MIN_EV (-10.0)
#define AGX_MAX_EV 6.5
#define AGX_SLOPE 2.4
#define AGX_POWER 1.5
#define AGX_HUE_KEPT 0.4

static void mat3_apply(const Mat3 m, const double in[3], double out[3])
{
    for (int r = 0; r < 3; r++) out[r] = m[r][0] * in[0] + m[r][1] * in[1] + m[r][2] * in[2];
}

static void mat3_inverse(const Mat3 m, Mat3 inv)
{
    double c00 = m[1][1] * m[2][2] - m[1][2] * m[2][1], c01 = m[1][2] * m[2][0] - m[1][0] * m[2][2],
           c02 = m[1][0] * m[2][1] - m[1][1] * m[2][0];
    double det = m[0][0] * c00 + m[0][1] * c01 + m[0][2] * c02;
    inv[0][0] = c00 / det;
    inv[1][0] = c01 / det;
    inv[2][0] = c02 / det;
    inv[0][1] = (m[0][2] * m[2][1] - m[0][1] * m[2][2]) / det;
    inv[1][1] = (m[0][0] * m[2][2] - m[0][2] * m[2][0]) / det;
    inv[2][1] = (m[0][1] * m[2][0] - m[0][0] * m[2][1]) / det;
    inv[0][2] = (m[0][1] * m[1][2] - m[0][2] * m[1][1]) / det;
    inv[1][2] = (m[0][2] * m[1][0] - m[0][0] * m[1][2]) / det;
    inv[2][2] = (m[0][0] * m[1][1] - m[0][1] * m[1][0]) / det;
}

static double max3(const double v[3]) { return fmax(v[0], fmax(v[1], v[2])); }
static double min3(const double v[3]) { return fmin(v[0], fmin(v[1], v[2])); }
static double dot3(const double a[3], const double b[3]) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

/* The luminance of c with its negative part counted through its opponent colour
 * (max - c): what the guard rail keeps. */
static double opponent_luminance(const double c[3])
{
    double inv[3] = { max3(c) - c[0], max3(c) - c[1], max3(c) - c[2] };
    return max3(inv) - dot3(inv, rec2020_luminance) + dot3(c, rec2020_luminance);
}

/* Step 2: no negative channel leaves it, and a colour that had one is no brighter than
 * before. */
static void agx_guard_rail(double c[3])
{
    double offset = -min3(c);
    if (!(offset > 0.0)) return;
    double target = opponent_luminance(c);
    for (int k = 0; k < 3; k++) c[k] += offset;
    double now = opponent_luminance(c);
    double ratio = now > target ? (now > 0.0 && target > 0.0 ? target / now : 0.0) : 1.0;
    for (int k = 0; k < 3; k++) c[k] *= ratio;
}

/* Jed Smith's sigmoid: the scale that takes a hyperbolic segment leaving the fulcrum at
 * `slope` through the limit dx, dy away. */
static double sigmoid_scale(double dx, double dy)
{
    return pow(pow(AGX_SLOPE * dx, -AGX_POWER) * (pow(AGX_SLOPE * dx / dy, AGX_POWER) - 1.0), -1.0 / AGX_POWER);
}

double view_agx_sigmoid(double x)
{
    if (x <= 0.0) return 0.0;   /* the toe ends at (0, 0); computed, it leaves 1e-16 */
    const double px = -AGX_MIN_EV / (AGX_MAX_EV - AGX_MIN_EV), py = pow(0.18, 1.0 / 2.4);
    /* toe below the fulcrum (towards (0,0)), shoulder above it (towards (1,1)) */
    double scale = x < px ? -sigmoid_scale(px, py) : sigmoid_scale(1.0 - px, 1.0 - py);
    double t = AGX_SLOPE * (x - px) / scale;
    return scale * t / pow(1.0 + pow(t, AGX_POWER), 1.0 / AGX_POWER) + py;
}

/* Step 4: 0.18 * 2^-10 and below give 0, 0.18 * 2^6.5 and above 1. */
static double agx_log2(double v)
{
    if (!(v > 0.0)) return 0.0;
    double x = (log2(v / 0.18) - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV);
    return x < 0.0 ? 0.0 : (x > 1.0 ? 1.0 : x);
}

/* Hexcone HSV hue in [0, 1) (0 for greys), and the colour of hue h, saturation s and
 * value v. */
static double hsv_hue(const double c[3])
{
    double hi = max3(c), d = hi - min3(c), h;
    if (!(d > 0.0)) return 0.0;
    if (hi == c[0]) h = (c[1] - c[2]) / d;
    else if (hi == c[1]) h = 2.0 + (c[2] - c[0]) / d;
    else h = 4.0 + (c[0] - c[1]) / d;
    h /= 6.0;
    return h < 0.0 ? h + 1.0 : h;
}

static void hsv_with_hue(double c[3], double h)
{
    double v = max3(c), d = v - min3(c);
    if (!(d > 0.0)) return;   /* a grey has no hue to set */
    double s = d / v, f = h * 6.0 - floor(h * 6.0);
    int sector = (int)floor(h * 6.0) % 6;
    double p = v * (1.0 - s), q = v * (1.0 - s * f), t = v * (1.0 - s * (1.0 - f));
    double out[6][3] = { { v, t, p }, { q, v, p }, { p, v, t }, { p, q, v }, { t, p, v }, { v, p, q } };
    for (int k = 0; k < 3; k++) c[k] = out[sector < 0 ? sector + 6 : sector][k];
}

static void agx_pixel(const double in[3], double out[3])
{
    Mat3 outset;   /* 30 operations, against the pixel's logs and powers */
    mat3_inverse(agx_outset_inverse, outset);
    double c[3], inset[3];
    mat3_apply(rec709_to_rec2020, in, c);
    agx_guard_rail(c);
    mat3_apply(agx_inset, c, inset);
    double hue_before = hsv_hue(inset);
    for (int k = 0; k < 3; k++) c[k] = pow(view_agx_sigmoid(agx_log2(inset[k])), 2.4);
    double hue_after = hsv_hue(c);
    hsv_with_hue(c, (1.0 - AGX_HUE_KEPT) * hue_before + AGX_HUE_KEPT * hue_after);
    double display[3];
    mat3_apply((const double(*)[3])outset, c, display);
    mat3_apply(rec2020_to_rec709, display, out);
}

/* Hable's curve: ((x(Ax + CB) + DE) / (x(Ax + B) + DF)) - E/F, with his constants. */
static double hable(double x)
{
    const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

double view_filmic_curve(double x)
{
    const double exposure_bias = 2.0, white = 11.2;
    return hable(x * exposure_bias) / hable(white);
}

static double clip01(double x) { return x > 0.0 ? (x < 1.0 ? x : 1.0) : 0.0; }   /* NaN: 0 */

int view_look_is_identity(const ViewLook *look)
{
    return look->view == VIEW_STANDARD && look->exposure == 0.0;
}

void view_pixel(const ViewLook *look, const float in[3], float out[3])
{
    double scale = exp2(look->exposure), c[3], d[3];
    /* NaN and -inf are no light; +inf stays, and every view makes it white */
    for (int k = 0; k < 3; k++) c[k] = isnan(in[k]) || in[k] == -INFINITY ? 0.0 : (double)in[k] * scale;
    switch (look->view) {
    case VIEW_AGX:
        /* the matrices would turn one infinite channel into NaN elsewhere: saturate
         * first, far beyond the +6.5 stops where AgX is white */
        for (int k = 0; k < 3; k++) c[k] = fmax(fmin(c[k], 1e30), -1e30);
        agx_pixel(c, d);
        break;
    case VIEW_FILMIC:
        /* Hable's rational curve tends to A/A = 1.37 x white at infinity and is not
         * monotonic below 0: values outside [0, inf) are clipped first */
        for (int k = 0; k < 3; k++) d[k] = c[k] > 0.0 ? (isinf(c[k]) ? 1.0 : view_filmic_curve(c[k])) : 0.0;
        break;
    case VIEW_STANDARD:
    default:
        for (int k = 0; k < 3; k++) d[k] = c[k];
        break;
    }
    for (int k = 0; k < 3; k++) out[k] = (float)clip01(d[k]);
}

void view_apply(const ViewLook *look, float *rgb, size_t n_pixels)
{
    for (size_t i = 0; i < n_pixels; i++) view_pixel(look, rgb + 3 * i, rgb + 3 * i);
}

const char *view_name(ViewTransform v)
{
    switch (v) {
    case VIEW_AGX: return "agx";
    case VIEW_FILMIC: return "filmic";
    case VIEW_STANDARD: return "standard";
    }
    return "standard";
}
