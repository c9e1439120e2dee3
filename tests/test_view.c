/*
 * test_view.c — the view transforms and exposure (io/view_transform.h) on known values:
 * black, middle grey 0.18, white, huge, infinite, negative and NaN inputs, against the
 * published formulas; and the styled writer: the standard view at exposure 0 writes the
 * bytes it wrote before views existed.
 *
 * The AgX numbers marked "reference" were computed by a separate port (Python, numpy) of
 * the published sigmoid (Jed Smith's tunable sigmoid as sobotka/SB2383's sigmoid.py
 * states it, through its general case: breakpoints, scales, the linear section) and of
 * the log2 encoding, not by the C code under test.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "harness.h"
#include "io/image_write.h"
#include "io/view_transform.h"

static void grey(const ViewLook *look, float v, float out[3])
{
    float in[3] = { v, v, v };
    view_pixel(look, in, out);
}

/* Hable's curve, written out here from his post: ((x(Ax+CB)+DE)/(x(Ax+B)+DF)) - E/F. */
static double hable_reference(double x)
{
    const double A = 0.15, B = 0.50, C = 0.10, D = 0.20, E = 0.02, F = 0.30;
    return (x * (A * x + C * B) + D * E) / (x * (A * x + B) + D * F) - E / F;
}

static void test_agx_sigmoid(void)
{
    /* through (0,0), the fulcrum (10/16.5, 0.18^(1/2.4)) and (1,1) */
    CHECK_EQ_INT(view_agx_sigmoid(0.0) == 0.0, 1);
    CHECK_NEAR(view_agx_sigmoid(1.0), 1.0, 1e-12);
    CHECK_NEAR(view_agx_sigmoid(10.0 / 16.5), pow(0.18, 1.0 / 2.4), 1e-12);
    /* the slope at the fulcrum is 2.4, from either side */
    double px = 10.0 / 16.5, h = 1e-7;
    CHECK_NEAR((view_agx_sigmoid(px + h) - view_agx_sigmoid(px)) / h, 2.4, 1e-4);
    CHECK_NEAR((view_agx_sigmoid(px) - view_agx_sigmoid(px - h)) / h, 2.4, 1e-4);
    /* reference values on the toe and the shoulder */
    CHECK_NEAR(view_agx_sigmoid(0.25), 0.06499235632416217, 1e-12);
    CHECK_NEAR(view_agx_sigmoid(0.8), 0.8407495052554048, 1e-12);
    /* rising everywhere */
    int rising = 1;
    for (int i = 1; i <= 1000; i++) rising &= view_agx_sigmoid(i / 1000.0) > view_agx_sigmoid((i - 1) / 1000.0);
    CHECK(rising);
}

static void test_agx_known_values(void)
{
    ViewLook agx = { VIEW_AGX, 0.0 };
    float out[3];
    /* greys stay grey: every matrix of the chain maps white to white */
    const float in[] = { 0.18f, 1.0f, 0.5f, 4.0f, 0.01f };
    const double reference[] = { 0.18, 0.5559990645351948, 0.4007472076391206, 0.8154117871922618,
                                 0.006262409256097056 };
    for (int i = 0; i < 5; i++) {
        grey(&agx, in[i], out);
        for (int k = 0; k < 3; k++) CHECK_NEAR(out[k], reference[i], 2e-6);
    }
    /* black, and what counts as no light: NaN, negative greys, -inf */
    const float dark[] = { 0.0f, NAN, -1.0f, -INFINITY, 0.18f / 2048.0f };
    for (int i = 0; i < 5; i++) {
        grey(&agx, dark[i], out);
        CHECK_MSG(out[0] == 0.0f && out[1] == 0.0f && out[2] == 0.0f, "input %g gives %g %g %g", (double)dark[i],
                  (double)out[0], (double)out[1], (double)out[2]);
    }
    /* +6.5 stops over middle grey and beyond: white, +inf included */
    const float bright[] = { 0.18f * 90.6f, 1e6f, 3e38f, INFINITY };
    for (int i = 0; i < 4; i++) {
        grey(&agx, bright[i], out);
        for (int k = 0; k < 3; k++) CHECK_NEAR(out[k], 1.0, 1e-6);
    }
    /* colours: finite, in [0,1], the dominant channel still dominant; a bright red goes
     * towards white (AgX's desaturation) */
    const float colours[][3] = { { 1, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, { 50, 0, 0 }, { -0.5f, 0.3f, 0.2f },
                                 { INFINITY, 0, 0 }, { NAN, 1, 0 } };
    for (int i = 0; i < 7; i++) {
        view_pixel(&agx, colours[i], out);
        for (int k = 0; k < 3; k++)
            CHECK_MSG(out[k] >= 0.0f && out[k] <= 1.0f, "colour %d channel %d: %g", i, k, (double)out[k]);
    }
    view_pixel(&agx, colours[0], out);
    CHECK(out[0] > out[1] && out[0] > out[2]);
    float red50[3];
    view_pixel(&agx, colours[3], red50);
    CHECK(red50[1] > out[1] && red50[2] > out[2]);
}

static void test_filmic_known_values(void)
{
    ViewLook filmic = { VIEW_FILMIC, 0.0 };
    float out[3];
    const float in[] = { 0.18f, 1.0f, 3.0f };
    for (int i = 0; i < 3; i++) {
        grey(&filmic, in[i], out);
        double want = hable_reference(2.0 * in[i]) / hable_reference(11.2);
        for (int k = 0; k < 3; k++) CHECK_NEAR(out[k], want, 1e-6);
    }
    CHECK_NEAR(view_filmic_curve(0.18), 0.12833844885562762, 1e-12);
    CHECK_NEAR(view_filmic_curve(5.6), 1.0, 1e-12);   /* white: 11.2 after the bias of 2 */
    const float dark[] = { 0.0f, NAN, -1.0f, -INFINITY };
    for (int i = 0; i < 4; i++) {
        grey(&filmic, dark[i], out);
        CHECK_MSG(out[0] == 0.0f, "input %g gives %g", (double)dark[i], (double)out[0]);
    }
    const float bright[] = { 5.6f, 1e6f, INFINITY };
    for (int i = 0; i < 3; i++) {
        grey(&filmic, bright[i], out);
        CHECK_NEAR(out[0], 1.0, 1e-6);
    }
}

static void test_standard_and_exposure(void)
{
    ViewLook standard = { VIEW_STANDARD, 0.0 }, plus1 = { VIEW_STANDARD, 1.0 }, minus2 = { VIEW_STANDARD, -2.0 };
    float out[3];
    CHECK(view_look_is_identity(&standard));
    CHECK(!view_look_is_identity(&plus1));
    grey(&standard, 0.18f, out);
    CHECK(out[0] == 0.18f);
    grey(&plus1, 0.18f, out);
    CHECK(out[0] == 0.36f);
    grey(&minus2, 2.0f, out);
    CHECK(out[0] == 0.5f);
    grey(&plus1, 0.75f, out);     /* clipped at 1 */
    CHECK(out[0] == 1.0f);
    grey(&standard, NAN, out);
    CHECK(out[0] == 0.0f);
    grey(&standard, -3.0f, out);
    CHECK(out[0] == 0.0f);
    /* exposure comes before the view: 0.09 at +1 EV is 0.18 at 0 */
    ViewLook agx1 = { VIEW_AGX, 1.0 }, agx0 = { VIEW_AGX, 0.0 };
    float a[3], b[3];
    grey(&agx1, 0.09f, a);
    grey(&agx0, 0.18f, b);
    CHECK_NEAR(a[0], b[0], 1e-7);
    CHECK(!strcmp(view_name(VIEW_AGX), "agx") && !strcmp(view_name(VIEW_FILMIC), "filmic") &&
          !strcmp(view_name(VIEW_STANDARD), "standard"));
}

static int read_bytes(const char *path, unsigned char **data, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    fseek(f, 0, SEEK_END);
    *len = (size_t)ftell(f);
    fseek(f, 0, SEEK_SET);
    *data = malloc(*len ? *len : 1);
    size_t got = *data ? fread(*data, 1, *len, f) : 0;
    fclose(f);
    return got == *len ? 0 : -1;
}

/* The styled writer: the identity look writes image_write_encoded's bytes; a view
 * changes a PNG; a float format with a look is refused by image_check_look. */
static void test_styled_writer(void)
{
    enum { W = 8, H = 4 };
    float rgb[W * H * 3];
    for (int i = 0; i < W * H * 3; i++) rgb[i] = (float)i / 20.0f;
    rgb[0] = NAN;
    rgb[1] = INFINITY;
    rgb[2] = -1.0f;
    char a[] = "/tmp/clpt-test-view-a-XXXXXX.png", b[] = "/tmp/clpt-test-view-b-XXXXXX.png";
    int fa = mkstemps(a, 4), fb = mkstemps(b, 4);
    if (fa >= 0) close(fa);
    if (fb >= 0) close(fb);
    Error err = { 0 };
    ImageStyle same = { IMAGE_SRGB, { VIEW_STANDARD, 0.0 }, 0 }, agx = { IMAGE_SRGB, { VIEW_AGX, 0.5 }, 0 };
    CHECK(image_write_encoded(a, rgb, W, H, IMAGE_SRGB, &err) == ST_OK);
    CHECK(image_write_styled(b, rgb, W, H, &same, &err) == ST_OK);
    unsigned char *da = NULL, *db = NULL;
    size_t la = 0, lb = 0;
    CHECK(read_bytes(a, &da, &la) == 0 && read_bytes(b, &db, &lb) == 0);
    CHECK(la == lb && da && db && memcmp(da, db, la) == 0);
    free(db);
    db = NULL;
    CHECK(image_write_styled(b, rgb, W, H, &agx, &err) == ST_OK);
    CHECK(read_bytes(b, &db, &lb) == 0);
    CHECK(!(la == lb && da && db && memcmp(da, db, la) == 0));
    free(da);
    free(db);
    unlink(a);
    unlink(b);
    CHECK_EQ_INT(image_check_look("out.exr", &agx.look, &err), ST_USAGE);
    CHECK_STR_CONTAINS(err.msg, "--view and --exposure form the picture of 8-bit images; 'out.exr' keeps the linear "
                                "radiance");
    CHECK_EQ_INT(image_check_look("out.exr", &same.look, &err), ST_OK);
    CHECK_EQ_INT(image_check_look("out.png", &agx.look, &err), ST_OK);
    error_clear(&err);
}

int main(void)
{
    RUN(test_agx_sigmoid);
    RUN(test_agx_known_values);
    RUN(test_filmic_known_values);
    RUN(test_standard_and_exposure);
    RUN(test_styled_writer);
    return harness_report();
}
