/* blackbody.c — a blackbody's colour in linear sRGB (see blackbody.h). */
#include "scene/blackbody.h"

#include "util/kmath.h"

#include <math.h>

/* CIE 1931 colour matching functions, the multi-lobe Gaussian fit of Wyman, Sloan and
 * Shirley (JCGT 2013); enough for a blackbody's colour to a few parts in a thousand. */
static double g_lobe(double x, double mu, double s1, double s2)
{
    double t = (x - mu) / (x < mu ? s1 : s2);
    return exp(-0.5 * t * t);
}

static void cie_xyz(double nm, double *x, double *y, double *z)
{
    *x = 1.056 * g_lobe(nm, 599.8, 37.9, 31.0) + 0.362 * g_lobe(nm, 442.0, 16.0, 26.7) -
         0.065 * g_lobe(nm, 501.1, 20.4, 26.2);
    *y = 0.821 * g_lobe(nm, 568.8, 46.9, 40.5) + 0.286 * g_lobe(nm, 530.9, 16.3, 31.1);
    *z = 1.217 * g_lobe(nm, 437.0, 11.8, 36.0) + 0.681 * g_lobe(nm, 459.0, 26.0, 13.8);
}

/* The constants of Planck's law, B(l, T) = 2 h c^2 / (l^5 (exp(h c / (l kb T)) - 1)), the
 * spectral radiance at wavelength l metres (CODATA 2010 values). */
static const double planck_c = 299792458.0, planck_h = 6.62606957e-34, planck_kb = 1.3806488e-23;

/* XYZ (D65 white) to linear sRGB, the out-of-gamut channels clamped to 0. */
static vec3 xyz_to_srgb(double X, double Y, double Z)
{
    double r = 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z;
    double g = -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z;
    double b = 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z;
    return v3((float)fmax(r, 0), (float)fmax(g, 0), (float)fmax(b, 0));
}

vec3 blackbody_rgb_unit_luminance(double kelvin)
{
    const double c = planck_c, h = planck_h, kb = planck_kb;
    double X = 0, Y = 0, Z = 0;
    for (double nm = 360.0; nm <= 830.0; nm += 1.0) {
        double l = nm * 1e-9;
        double le = (2 * h * c * c) / (pow(l, 5) * (exp((h * c) / (l * kb * kelvin)) - 1));
        double x, y, z;
        cie_xyz(nm, &x, &y, &z);
        X += le * x;
        Y += le * y;
        Z += le * z;
    }
    if (!(Y > 0) || !isfinite(Y)) return v3(1, 1, 1);
    X /= Y;
    Z /= Y;
    Y = 1;
    return xyz_to_srgb(X, Y, Z);
}

void blackbody_table_init(BlackbodyTable *t)
{
    t->y_integral = 0.0;
    for (int i = 0; i < 471; i++) {
        cie_xyz(360.0 + i, &t->xyz[i][0], &t->xyz[i][1], &t->xyz[i][2]);
        t->y_integral += t->xyz[i][1];
    }
}

vec3 blackbody_rgb_peak_normalised(const BlackbodyTable *t, double kelvin)
{
    if (!(kelvin > 0)) return v3s(0.0f);
    const double c = planck_c, h = planck_h, kb = planck_kb;
    /* Wien's displacement law: the peak wavelength, where Planck's law is divided by itself */
    double peak = 2.8977721e-3 / kelvin;
    double p5 = peak * peak * peak * peak * peak;
    double at_peak = (2 * h * c * c) / (p5 * expm1((h * c) / (peak * kb * kelvin)));
    double X = 0, Y = 0, Z = 0;
    for (int i = 0; i < 471; i++) {
        double l = (360.0 + i) * 1e-9;
        double l5 = l * l * l * l * l;
        double le = (2 * h * c * c) / (l5 * expm1((h * c) / (l * kb * kelvin))) / at_peak;
        X += le * t->xyz[i][0];
        Y += le * t->xyz[i][1];
        Z += le * t->xyz[i][2];
    }
    if (!isfinite(X) || !isfinite(Y) || !isfinite(Z)) return v3s(0.0f);
    return xyz_to_srgb(X, Y, Z);
}
