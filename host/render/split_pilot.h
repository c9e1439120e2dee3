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
 * samples per pixel twice, with two seeds of its own, at each split it measures
 * (SPLIT_PILOT_MEASURED). Each split's error is the squared difference of its two films
 * (two independent estimates of every pixel), relative to the pixel's value in a third
 * film of split 1 that weighs every split alike (SPLIT_PILOT_REL_EPS; split_pilot.c,
 * weigh), its cost the rays it traced. The readings are noisy where a few pixels hold
 * the error (a highlight of the sun, a glint of a lamp): one split's reading may be
 * 20-60% off on one grid and not on another (envmat's split 16 reads 0.32-0.89 of split
 * 1's error x rays on nine grids in ten, 0.59 over whole images). So the choice is
 * not taken from the readings one by one but from the curve they fit together: the
 * parabola in log2 N of least squares through the readings' log(error x rays) (the
 * curve of a split's efficiency is convex with one minimum, where what the camera
 * sample's own error costs balances the continuations' rays), evaluated at every
 * candidate (SPLIT_PILOT_CANDIDATES). The render takes the one of least fitted error x
 * rays (efficiency as variance x cost, the measure of Veach's thesis, 1997, section
 * 2.4.1), splitting at all only where that is below SPLIT_PILOT_GAIN of the fitted split 1.
 * A fit of the model of two-stage sampling, error V0 + V1 / N for rays R0 + R1 N (whose
 * best N Cochran's "Sampling Techniques", 1977, chapter 10, derives), chose better than
 * the parabola on most scenes but kept one-weekend at split 1 in a third of the
 * simulated pilots, where it gains a quarter at 2 and 4: Sobol points make the
 * continuations' error fall faster than 1 / N.
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

/* The splits a render may take, and how many of them the pilot measures (SPLIT_PILOT_MEASURED,
 * split_pilot.c: 1, 2, 4 and 16; the parabola puts 8 between 4 and 16). Every reading
 * goes into the fit: pilots simulated from independent renders of ten scenes chose
 * within 0-5% of the best split's efficiency on average, where taking the least reading
 * after the go-on rule of before was 1-11% from it (envmat: 0.620 and 0.659 of split 1's
 * error x rays, the best 0.592; bench/RESULTS.md, "The split pilot's curve"). */
#define SPLIT_PILOT_CANDIDATES 5
#define SPLIT_PILOT_MEASURED 4
/* Splitting at all is chosen where the fitted error x rays is below this share of
 * split 1's (the estimates are noisy, and on a GPU a split render also runs the
 * megakernel). */
#define SPLIT_PILOT_GAIN 0.9
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

/* The fitted curve: log(error x rays) at N continuations is c0 + c1 x + c2 x^2,
 * x = log2 N. */
typedef struct {
    double c0, c1, c2;
} SplitModel;

typedef struct {
    uint chosen;                 /* the split the render uses (1 when the pilot did not run) */
    int ran;                     /* the pilot rendered (split auto, a path-traced render large enough) */
    uint pixels, spp;            /* its pixels and samples per pixel */
    uint measured;               /* how many splits it rendered */
    uint split[SPLIT_PILOT_MEASURED];
    double error[SPLIT_PILOT_MEASURED];   /* the films' relative squared difference, summed over
                                           * pixels and channels */
    uint64_t rays[SPLIT_PILOT_MEASURED];
    int fitted;                  /* model holds the fit (split_pilot_fit) */
    SplitModel model;
    double seconds;
} SplitPilot;

/* The pilot's pixels and samples per pixel for a width x height image: *stride the
 * grid's step in both directions; 0 for an image too small for a pilot. Pure, for the
 * tests. */
uint split_pilot_plan(uint width, uint height, uint *stride, uint *pilot_spp);

/* The splits a render may take, SPLIT_PILOT_CANDIDATES of them in increasing order,
 * and the ones the pilot measures, SPLIT_PILOT_MEASURED, split 1 first. */
extern const uint split_pilot_candidates[SPLIT_PILOT_CANDIDATES];
extern const uint split_pilot_measured_splits[SPLIT_PILOT_MEASURED];

/* Fits the curve to what sp measured by least squares. 0 (and no curve) where fewer
 * than three splits were measured or a reading is not positive (a scene without
 * noise). The logarithm is the one step whose last bit may differ between two
 * machines' maths libraries; a choice could then differ only where two candidates'
 * fitted costs agree to 15 digits. Pure, for the tests. */
int split_pilot_fit(const SplitPilot *sp, SplitModel *m);

/* The fitted error x rays at split n. */
double split_model_cost(const SplitModel *m, uint n);

/* The candidate of least fitted cost, where it is below SPLIT_PILOT_GAIN of split 1's;
 * else (or without a fit) 1. Pure, for the tests. */
uint split_pilot_choose(const SplitPilot *sp);

/* Runs the pilot for run->rs when its params ask for split auto (RenderParams.split 0)
 * on the path tracer with the camera in vacuum, and writes the chosen split into the params (and so
 * to the devices, with update_params): 1 without a pilot. The params' pixel list and
 * sample step are restored. An interrupt during the pilot chooses 1. */
Status split_pilot_run(const AdaptiveRun *run, SplitPilot *sp, Error *err);

#endif /* CLPT_SPLIT_PILOT_H */
