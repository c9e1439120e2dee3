/*
 * test_split_pilot.c — `--split auto` (host/render/split_pilot.h): which pixels and
 * samples the pilot renders, and how it chooses from what it measured. The pilot's
 * renders themselves (the same choice on every device, and the image of that split)
 * are checked in test_cli.c.
 */
#include "harness.h"
#include "render/split_pilot.h"

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

static SplitPilot measured(uint n, const double *error, const uint64_t *rays)
{
    SplitPilot sp = { 0 };
    static const uint splits[] = { 1, 2, 4, 8, 16 };
    for (uint i = 0; i < n; i++) {
        sp.split[i] = splits[i];
        sp.error[i] = error[i];
        sp.rays[i] = rays[i];
    }
    sp.measured = n;
    return sp;
}

/* Least error x rays; splitting at all for a gain of SPLIT_PILOT_GAIN or more, a larger
 * split for SPLIT_PILOT_GAIN_MORE. */
static void test_choose(void)
{
    const uint64_t rays[] = { 1000, 1600, 2800, 5200, 10000 };
    /* split 2 halves the error for 1.6 times the rays: 0.8 of split 1's */
    SplitPilot sp = measured(2, (const double[]){ 1.0, 0.5 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 2);
    /* 0.92: not enough to split */
    sp = measured(2, (const double[]){ 1.0, 0.575 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 1);
    /* split 4 after split 2: 0.8 then 0.7 of split 1's (0.875 of split 2's) */
    sp = measured(3, (const double[]){ 1.0, 0.5, 0.25 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 4);
    /* split 4 at 0.93 of split 2's: enough to split more */
    sp = measured(3, (const double[]){ 1.0, 0.5, 0.265 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 4);
    /* split 4 at 0.98 of split 2's: not */
    sp = measured(3, (const double[]){ 1.0, 0.5, 0.28 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 2);
    /* split 8 after 4 */
    sp = measured(4, (const double[]){ 1.0, 0.5, 0.25, 0.12 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 8);
    /* split 16 after 8: 0.624 then 0.55 of split 1's (0.88 of split 8's) */
    sp = measured(5, (const double[]){ 1.0, 0.5, 0.25, 0.12, 0.055 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 16);
    /* split 16 at 0.96 of split 8's (the dragon's pilot, about): 8 */
    sp = measured(5, (const double[]){ 1.0, 0.5, 0.25, 0.12, 0.06 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 8);
    /* a later split compared with the choice, not with the one measured before it:
     * 2 not enough (0.96), 4 at 0.84 of split 1's */
    sp = measured(3, (const double[]){ 1.0, 0.6, 0.3 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 4);
    /* nothing measured (an interrupted pilot) */
    sp = measured(0, (const double[]){ 0.0 }, rays);
    CHECK_EQ_INT(split_pilot_choose(&sp), 1);
}

/* The first SPLIT_PILOT_ALWAYS candidates are measured whatever they read; then the next
 * while the last is within SPLIT_PILOT_GO_ON of the least error x rays so far, whether
 * or not it won. */
static void test_go_on(void)
{
    const uint64_t rays[] = { 1000, 1600, 2800, 5200, 10000 };
    CHECK_EQ_INT(SPLIT_PILOT_ALWAYS, 3);
    CHECK_EQ_INT(split_pilot_go_on(&(SplitPilot){ 0 }), 1);
    /* 2 and 4 at 0.80 and 0.84 of split 1's: 4 did not win, but it is within 1.2 of 2 */
    SplitPilot sp = measured(3, (const double[]){ 1.0, 0.5, 0.3 }, rays);
    CHECK_EQ_INT(split_pilot_go_on(&sp), 1);
    CHECK_EQ_INT(split_pilot_choose(&sp), 2);
    /* 4 at 1.12: more than 1.2 times 2's 0.80 */
    sp = measured(3, (const double[]){ 1.0, 0.5, 0.4 }, rays);
    CHECK_EQ_INT(split_pilot_go_on(&sp), 0);
    /* 2 read worse than 1 (noise) and 4 within 1.2 of 1: on to 8, which wins */
    sp = measured(4, (const double[]){ 1.0, 0.7, 0.4, 0.12 }, rays);
    CHECK_EQ_INT(split_pilot_go_on(&sp), 1);
    CHECK_EQ_INT(split_pilot_choose(&sp), 8);
}

int main(void)
{
    RUN(test_plan);
    RUN(test_choose);
    RUN(test_go_on);
    return harness_report();
}
