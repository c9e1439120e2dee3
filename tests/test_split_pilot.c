/*
 * test_split_pilot.c — `--split auto` (host/render/split_pilot.h): which pixels and
 * samples the pilot renders, and how it chooses from what it measured. The pilot's
 * renders themselves (the same choice on every device, and the image of that split)
 * are checked in test_cli.c.
 */
#include "harness.h"
#include "render/split_pilot.h"

#include <math.h>

/* The grid covers the image evenly and holds at least SPLIT_PILOT_MIN_PIXELS (or a
 * 128th of a large image); an image too small for a pilot gets none. Nothing depends on
 * the samples per pixel: a render grown to more samples chooses as it did. */
static void test_plan(void)
{
    uint stride, spp;
    /* 512 x 512: a 121st of the pixels (2209) */
    CHECK_EQ_INT(split_pilot_plan(512, 512, &stride, &spp), 2209);
    CHECK_EQ_INT(stride, 11);
    CHECK_EQ_INT(spp, SPLIT_PILOT_SPP);
    /* 4096 x 2160: a 128th of the pixels or more */
    uint n = split_pilot_plan(4096, 2160, &stride, &spp);
    CHECK_MSG(n >= 4096u * 2160u / 128u && n < 4096u * 2160u / 100u, "%u pixels, stride %u", n, stride);
    /* 400 x 225 (one-weekend.scene): 1024 pixels or more, a stride of 9 */
    n = split_pilot_plan(400, 225, &stride, &spp);
    CHECK_MSG(n >= SPLIT_PILOT_MIN_PIXELS && stride == 9u, "%u pixels, stride %u", n, stride);
    /* too small for a pilot, or nothing at all */
    CHECK_EQ_INT(split_pilot_plan(255, 256, &stride, &spp), 0);
    CHECK_EQ_INT(stride, 0);
    CHECK_EQ_INT(split_pilot_plan(256, 256, &stride, &spp), 1024);
    CHECK_EQ_INT(split_pilot_plan(0, 0, &stride, &spp), 0);
}

/* A pilot that measured error x rays e[i] (split 1's rays 1000, 600 more per
 * continuation) at each of split_pilot_measured_splits, with its fit. */
static SplitPilot readings(const double *e)
{
    SplitPilot sp = { 0 };
    for (uint i = 0; i < SPLIT_PILOT_MEASURED; i++) {
        sp.split[i] = split_pilot_measured_splits[i];
        sp.rays[i] = 1000u + 600u * (sp.split[i] - 1u);
        sp.error[i] = e[i] / (double)sp.rays[i];
    }
    sp.measured = SPLIT_PILOT_MEASURED;
    sp.fitted = split_pilot_fit(&sp, &sp.model);
    return sp;
}

/* error x rays exp(c0 + c1 x + c2 x^2) at x = log2 N of each measured split */
static SplitPilot on_curve(double c0, double c1, double c2)
{
    double e[SPLIT_PILOT_MEASURED];
    for (uint i = 0; i < SPLIT_PILOT_MEASURED; i++) {
        double x = log2((double)split_pilot_measured_splits[i]);
        e[i] = exp(c0 + c1 * x + c2 * x * x);
    }
    return readings(e);
}

/* Readings on a parabola in log2 N give it back; the candidates are 1, 2, 4, 8, 16 and
 * split 1 is measured first. */
static void test_fit(void)
{
    CHECK_EQ_INT(split_pilot_candidates[0], 1);
    CHECK_EQ_INT(split_pilot_candidates[SPLIT_PILOT_CANDIDATES - 1], 16);
    CHECK_EQ_INT(split_pilot_measured_splits[0], 1);
    CHECK(SPLIT_PILOT_MEASURED >= 3);
    SplitPilot sp = on_curve(2.0, -0.3, 0.05);
    CHECK(sp.fitted);
    CHECK_NEAR(sp.model.c0, 2.0, 1e-9);
    CHECK_NEAR(sp.model.c1, -0.3, 1e-9);
    CHECK_NEAR(sp.model.c2, 0.05, 1e-9);
    CHECK_NEAR(split_model_cost(&sp.model, 8u), exp(2.0 - 0.9 + 0.45), 1e-9);
    /* a reading without noise, or too few readings: no fit */
    sp = on_curve(2.0, -0.3, 0.05);
    sp.error[2] = 0.0;
    SplitModel m;
    CHECK_EQ_INT(split_pilot_fit(&sp, &m), 0);
    sp = on_curve(2.0, -0.3, 0.05);
    sp.measured = 2;
    CHECK_EQ_INT(split_pilot_fit(&sp, &m), 0);
}

/* The candidate of least fitted error x rays, splitting at all only below
 * SPLIT_PILOT_GAIN of split 1's fitted cost. */
static void test_choose(void)
{
    /* the curve's minimum at x = 3: split 8, at exp(-0.45) = 0.64 of split 1 */
    SplitPilot sp = on_curve(0.0, -0.3, 0.05);
    CHECK_EQ_INT(split_pilot_choose(&sp), 8);
    /* falling all the way: 16 */
    sp = on_curve(0.0, -0.2, 0.0);
    CHECK_EQ_INT(split_pilot_choose(&sp), 16);
    /* rising: 1 */
    sp = on_curve(0.0, 0.1, 0.02);
    CHECK_EQ_INT(split_pilot_choose(&sp), 1);
    /* the minimum at split 4 at exp(-0.05) = 0.95 of split 1: not enough to split */
    sp = on_curve(0.0, -0.05, 0.0125);
    CHECK_EQ_INT(split_pilot_choose(&sp), 1);
    /* at exp(-0.2) = 0.82: split 4 */
    sp = on_curve(0.0, -0.2, 0.05);
    CHECK_EQ_INT(split_pilot_choose(&sp), 4);
    /* what the pilot read on scenes/one-weekend.scene (400x225): 2 at 0.779, 4 at
     * 0.812, 16 at 2.039 of split 1; fitted 0.781 at 2, 0.810 at 4 */
    sp = readings((const double[]){ 1.0, 0.779, 0.812, 2.039 });
    CHECK_EQ_INT(split_pilot_choose(&sp), 2);
    /* bench-peers' envmat: 2 read at 0.747, 4 at 0.913, 16 at 0.941 (whole images: 0.79,
     * 0.71, 0.59); the least reading is split 2's, the curve's minimum split 4's
     * (0.825) */
    sp = readings((const double[]){ 1.0, 0.747, 0.913, 0.941 });
    CHECK_EQ_INT(split_pilot_choose(&sp), 4);
    /* no fit (an interrupted pilot, a scene without noise): 1 */
    sp = (SplitPilot){ 0 };
    CHECK_EQ_INT(split_pilot_choose(&sp), 1);
}

int main(void)
{
    RUN(test_plan);
    RUN(test_fit);
    RUN(test_choose);
    return harness_report();
}
