/*
 * split_pilot.h — `--split auto` (the default): how many continuations each camera
 * sample's first hit gets (first-hit splitting, docs/design.md), chosen per render by a
 * short pilot render that measures what each choice costs and what error it leaves.
 *
 * Splitting shares the camera ray and first hit among N continuations. It pays where
 * the camera ray is a large part of a sample's cost and the error is in what follows
 * the first hit (the dragon, environment-lit scenes), and costs where the error is the
 * camera sample's own (which surface a pixel's sample sees: silhouettes, a bright
 * lamp's edge). Which holds depends on the scene and on the samples per pixel (Sobol
 * points make both parts fall faster than 1/n, each at its own rate), so it is
 * measured rather than guessed: a sparse grid of pixels renders SPLIT_PILOT_SPP
 * samples per pixel twice, with two seeds of its own, at split 1, 2 and 4, then 8
 * and 16 while the last one came near the best (SPLIT_PILOT_GO_ON). Each split's error
 * is the squared difference of its two films (two independent estimates of every
 * pixel), relative to the pixel's value in a third film of split 1 that weighs every
 * split alike (SPLIT_PILOT_REL_EPS; split_pilot.c, weigh), its cost the rays it
 * traced; the render takes the N of least
 * error x rays, a larger N only where it promises at most SPLIT_PILOT_GAIN (from 1) or
 * SPLIT_PILOT_GAIN_MORE of the smaller one's (efficiency as variance x cost, the
 * measure of Veach's thesis, 1997, section 2.4.1).
 *
 * Ray counts and film sums are integers that every device, batch size and MPI rank
 * produce alike, the pilot's pixels and samples depend only on the image's size, and
 * the decision is taken in double arithmetic on the host: every device, rank, resume
 * and part (--sample-range) of a render chooses the same N, so a seed still gives the
 * same image everywhere. Rays, not seconds, because seconds differ between machines
 * (and they track seconds: the dragon's split 2 traces 1.61 times the rays of split 1
 * in 1.58 times the time, the McGuire box 1.84 in 1.85).
 */
#ifndef CLPT_SPLIT_PILOT_H
#define CLPT_SPLIT_PILOT_H

#include "render/adaptive.h"

/* The splits the pilot may measure, in order: the first SPLIT_PILOT_ALWAYS always, each
 * after them while the one before it came within SPLIT_PILOT_GO_ON of the least error x
 * rays so far. Not only after a win: a sparse grid's error is noisy where a few pixels
 * hold it (highlights), and stopping at the first split that did not win left
 * scenes/materials at split 1 in half of the pilots simulated from independent renders,
 * where 8 and 16 are at 0.69 and 0.66 of its error x rays (bench/RESULTS.md). */
#define SPLIT_PILOT_CANDIDATES 5
#define SPLIT_PILOT_ALWAYS 3
#define SPLIT_PILOT_GO_ON 1.2
/* Splitting at all is chosen where its error x rays is below this share of split 1's
 * (the estimates are noisy, and on a GPU a split render also runs the megakernel), a
 * larger split where it is below the second share of the smaller one's (noise alone). */
#define SPLIT_PILOT_GAIN 0.9
#define SPLIT_PILOT_GAIN_MORE 0.95
/* The pilot's samples per pixel in each of its two films. Fixed, as everything the
 * pilot does is by the image's size alone: a render of N samples per pixel is the first
 * N of one of more (a checkpoint or part grown to more, docs/checkpoint.md), so the
 * split must not depend on N. */
#define SPLIT_PILOT_SPP 8u
/* The grid holds at least this many pixels, or a 128th of a larger image. */
#define SPLIT_PILOT_MIN_PIXELS 1024u
/* Images of fewer pixels keep split 1 without a pilot: it renders 2 films x 8 samples
 * of a 128th of the pixels at split 1, 0.125 samples per pixel of the image, about 5.4
 * times that where it goes on to split 4 and 10.6 times to split 8 (where the render's
 * own samples cost 2.8 and 5.2 times split 1's); below 256 x 256 the grid's 1024 pixels
 * would be more than a 64th, and its cost twice that or more. */
#define SPLIT_PILOT_MIN_IMAGE (256u * 256u)
/* The error is relative (relMSE: a pixel's squared difference over its squared value
 * plus this, in radiance squared), as the error of images whose pixels span many stops
 * is measured in rendering research (Rousselle, Knaus and Zwicker 2011) and as Cycles'
 * noise threshold weighs it: the absolute error of a few pixels along the edge of a
 * lamp seen directly, white on any display, would otherwise outweigh the rest of the
 * image (on scenes/cornell-box.scene, 1% of the pixels held half the squared error,
 * and a pilot of a 121st of the pixels saw the whole image's split 2 at 0.81 of split
 * 1's error x rays where it is at 1.23; relative, 0.86 against the whole image's 0.86). */
#define SPLIT_PILOT_REL_EPS 0.01
/* The two films' seeds, the pilot's own: the choice is the scene's and the image
 * size's, the same whatever --seed a render is given (with the render's seed, envmat
 * chose split 4 for one seed and 8 for another). */
#define SPLIT_PILOT_SEED_A 0x9e3779b9u
#define SPLIT_PILOT_SEED_B 0x5bd1e995u
/* The seed of the film that weighs every split's error (split_pilot.c, weigh). */
#define SPLIT_PILOT_SEED_W 0x2545f491u

typedef struct {
    uint chosen;                 /* the split the render uses (1 when the pilot did not run) */
    int ran;                     /* the pilot rendered (split auto, a path-traced render large enough) */
    uint pixels, spp;            /* its pixels and samples per pixel */
    uint measured;               /* how many candidates it rendered */
    uint split[SPLIT_PILOT_CANDIDATES];
    double error[SPLIT_PILOT_CANDIDATES];   /* the films' relative squared difference, summed over
                                             * pixels and channels */
    uint64_t rays[SPLIT_PILOT_CANDIDATES];
    double seconds;
} SplitPilot;

/* The pilot's pixels and samples per pixel for a width x height image: *stride the
 * grid's step in both directions; 0 for an image too small for a pilot. Pure, for the
 * tests. */
uint split_pilot_plan(uint width, uint height, uint *stride, uint *pilot_spp);

/* The split of least error x rays among the measured candidates, each only where it
 * beats the choice before it by SPLIT_PILOT_GAIN (from split 1) or SPLIT_PILOT_GAIN_MORE.
 * Pure, for the tests. */
uint split_pilot_choose(const SplitPilot *sp);

/* Whether the pilot measures the next candidate: the last one measured is within
 * SPLIT_PILOT_GO_ON of the least error x rays measured. Pure, for the tests. */
int split_pilot_go_on(const SplitPilot *sp);

/* Runs the pilot for run->rs when its params ask for split auto (RenderParams.split 0)
 * on the path tracer with the camera in vacuum, and writes the chosen split into the params (and so
 * to the devices, with update_params): 1 without a pilot. The params' pixel list and
 * sample step are restored. An interrupt during the pilot chooses 1. */
Status split_pilot_run(const AdaptiveRun *run, SplitPilot *sp, Error *err);

#endif /* CLPT_SPLIT_PILOT_H */
