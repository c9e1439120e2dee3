/*
 * blackbody.h — the colour of a blackbody (Planck's law) in clpt's linear sRGB: its
 * spectrum integrated against the CIE 1931 colour matching functions, then XYZ to sRGB
 * (IEC 61966-2-1 primaries, D65 white). Two normalisations, as pbrt-v4 uses them:
 *  - a light's "blackbody" spectrum is divided by its luminance (pbrt-v4's
 *    SpectrumToPhotometric), so only its colour counts: blackbody_rgb_unit_luminance;
 *  - a medium's temperature emission is pbrt-v4's BlackbodySpectrum(T), Planck's law
 *    divided by its value at the peak wavelength (Wien's displacement law), recorded as
 *    pbrt-v4's RGB film with its default CIE 1931 sensor records it: X, Y, Z are the
 *    integrals of x-bar, y-bar, z-bar times the spectrum over nanometres, *not* divided
 *    by the integral of y-bar (about 106.9), since nothing puts this emission in
 *    photometric units as the lights are: blackbody_rgb_peak_normalised. A cell at
 *    6500 K thus glows about 100 times as bright as an RGB 1 1 1 light would. Pharr,
 *    Jakob, Humphreys, PBR 4th ed., sec. 4.4.1 (blackbody emitters), 4.6 (sensor
 *    response, PixelSensor::ToSensorRGB).
 * Channels outside the sRGB gamut (below about 1900 K blue is negative) are clamped to 0.
 */
#ifndef CLPT_BLACKBODY_H
#define CLPT_BLACKBODY_H

#include "types.h"

/* A light's blackbody at `kelvin` (> 0) as linear sRGB of luminance 1. */
vec3 blackbody_rgb_unit_luminance(double kelvin);

/* The colour matching functions sampled once, for many temperatures in a row (a grid's
 * cells): blackbody_rgb_peak_normalised evaluates only Planck's law per call. */
typedef struct {
    double xyz[471][3];     /* x-bar, y-bar, z-bar at 360, 361 ... 830 nm */
    double y_integral;      /* the sum of y-bar over those (1 nm steps): about 106.9 */
} BlackbodyTable;

void blackbody_table_init(BlackbodyTable *t);

/* A bound on every channel of blackbody_rgb_peak_normalised at any temperature (about
 * 130 at its largest, near 4560 K): readers check that an emission times it stays a
 * float. */
#define BLACKBODY_RGB_MAX 256.0f

/* pbrt-v4's BlackbodySpectrum(kelvin) (peak 1) as linear sRGB; 0 0 0 for kelvin <= 0. */
vec3 blackbody_rgb_peak_normalised(const BlackbodyTable *t, double kelvin);

#endif /* CLPT_BLACKBODY_H */
