/* options_parse.c — reading a command line through the flag table of options.c: long
 * and short flags, --opt=value, bundles (-qo x.png), "--" ending the flags, "did you
 * mean", and the checks that span several flags; and the library's one-flag setter
 * (options_set). Strict: every value is checked whole and in range. */
#include "options.h"

#include "course_args.h"

#include "device/device.h"
#include "io/image_write.h"
#include "io/scene_load.h"
#include "io/view_transform.h"
#include "render/adaptive.h"
#include "render/passes.h"
#include "scene/crop.h"
#include "base/limit.h"
#include "types.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The flag named `a` (its name or alias); NULL: none. */
static const OptionSpec *option_find(const char *a)
{
    for (size_t k = 0; options_flag(k); k++) {
        const OptionSpec *s = options_flag(k);
        if (strcmp(a, s->name) == 0 || (s->alias && strcmp(a, s->alias) == 0)) return s;
    }
    return NULL;
}

/* Levenshtein distance between two short words (a flag as typed and a listed one);
 * words past 63 characters are as far as can be. */
static size_t edit_distance(const char *a, const char *b)
{
    enum { MAX = 64 };
    size_t la = strlen(a), lb = strlen(b), row[MAX];
    if (la >= MAX || lb >= MAX) return (size_t)-1;
    for (size_t j = 0; j <= lb; j++) row[j] = j;
    for (size_t i = 1; i <= la; i++) {
        size_t diag = row[0];
        row[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t up = row[j];
            size_t best = diag + (a[i - 1] != b[j - 1]);
            if (up + 1 < best) best = up + 1;
            if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
            row[j] = best;
            diag = up;
        }
    }
    return row[lb];
}

/* The listed flag a mistyped `a` most likely meant: the nearest name, when it is at
 * most two edits away and those edits are fewer than half of what was typed (so that
 * "-x" suggests nothing); NULL: none is near. */
static const char *option_nearest(const char *a)
{
    const char *best = NULL;
    size_t best_d = 3, letters = strspn(a, "-") < strlen(a) ? strlen(a) - strspn(a, "-") : 0;
    for (size_t k = 0; options_flag(k); k++) {
        size_t d = edit_distance(a, options_flag(k)->name);
        if (d < best_d && 2 * d < letters + 1) {
            best_d = d;
            best = options_flag(k)->name;
        }
    }
    return best;
}

/* "unknown option '--sp'; did you mean '--spp'?" (main adds the one hint at --help). */
static Status option_unknown(const char *a, Error *err)
{
    const char *near = option_nearest(a);
    if (near) return error_set(err, ST_USAGE, "unknown option '%s'; did you mean '%s'?", a, near);
    return error_set(err, ST_USAGE, "unknown option '%s'", a);
}

/* One of a CHOICE flag's words (or of a SWITCH's after '=') into the int at dst. */
static Status option_set_choice(const OptionSpec *s, const char *a, const char *v, void *dst, Error *err)
{
    for (const OptionChoice *c = s->choices; c->name; c++)
        if (strcmp(v, c->name) == 0) {
            *(int *)dst = c->value;
            return ST_OK;
        }
    char expected[160];
    option_choices_text(s->choices, 1, expected, sizeof expected);
    return error_set(err, ST_USAGE, "%s expects %s, got '%s'", a, expected, v);
}

/* Reads v, the value of flag `a` (as typed; NULL for a switch given alone), into its
 * field of o. */
static Status option_set(const OptionSpec *s, const char *a, const char *v, Options *o, Error *err)
{
    void *dst = (char *)o + s->offset;
    long n = 0;
    Status st = ST_OK;
    switch (s->kind) {
    case OPTION_SWITCH:
        if (!v) {
            *(int *)dst = 1;
            return ST_OK;
        }
        if (!s->choices) return error_set(err, ST_USAGE, "%s takes no value, got '%s=%s'", a, a, v);
        return option_set_choice(s, a, v, dst, err);
    case OPTION_TEXT:
        if (!*v) return error_set(err, ST_USAGE, "%s needs a %s", a, s->what);
        *(const char **)dst = v;
        return ST_OK;
    case OPTION_LONG: return option_parse_long(a, v, s->lo, s->hi, (long *)dst, err);
    case OPTION_UINT:
        if (!(st = option_parse_long(a, v, s->lo, s->hi, &n, err))) *(unsigned *)dst = (unsigned)n;
        return st;
    case OPTION_INT:
        if (!(st = option_parse_long(a, v, s->lo, s->hi, &n, err))) *(int *)dst = (int)n;
        return st;
    case OPTION_SECONDS: return option_parse_seconds(a, v, (double *)dst, err);
    case OPTION_CHOICE: return option_set_choice(s, a, v, dst, err);
    case OPTION_CUSTOM: return s->parse(v, o, err);
    }
    return error_set(err, ST_INTERNAL, "%s: unknown kind of flag", a);
}

/* A switch given a value (the library's settings): on or off. */
static Status option_switch_value(const char *name, const char *v, int *dst, Error *err)
{
    static const char *const on[] = { "1", "on", "true", "yes" }, *const off[] = { "0", "off", "false", "no" };
    for (size_t i = 0; i < 4; i++)
        if (strcmp(v, on[i]) == 0 || strcmp(v, off[i]) == 0) {
            *dst = strcmp(v, on[i]) == 0;
            return ST_OK;
        }
    return error_set(err, ST_USAGE, "%s is a switch: expects 1, on, true or 0, off, false, got '%s'", name, v);
}

Status options_set(Options *o, const char *name, const char *value, Error *err)
{
    char flag[64];
    if (!name || !value) return error_set(err, ST_USAGE, "an option needs a name and a value");
    if (strncmp(name, "--", 2) == 0) name += 2;
    if (strlen(name) + 3 > sizeof flag) return error_set(err, ST_USAGE, "unknown option '%s'", name);
    snprintf(flag, sizeof flag, "--%s", name);
    const OptionSpec *s = option_find(flag);
    if (!s) return error_set(err, ST_USAGE, "unknown option '%s'", name);
    /* a switch with choices (--stats=json) also takes one of them by name */
    if (s->kind == OPTION_SWITCH && (!s->choices || option_switch_value(flag, value, &(int){ 0 }, NULL) == ST_OK))
        return option_switch_value(flag, value, (int *)(void *)((char *)o + s->offset), err);
    return option_set(s, flag, value, o, err);
}

void options_init(Options *o)
{
    memset(o, 0, sizeof *o);
    o->spp = o->width = o->height = o->seed = o->max_depth = o->split = -1;
    o->range_first = o->range_end = -1;
    o->frames_first = o->frames_last = -1;
    o->anim_time = -1.0;
    o->integrator = -1;
    o->gamma = -1;
    o->shadows = -1;
    o->sampler = -1;
    o->accel = -1;
    o->format = SCENE_FORMAT_AUTO;
    o->adaptive_spp = 0;   /* not given; 16 once options_finish has checked */
}

/* The one scene argument. */
static Status options_scene(const char *a, Options *o, Error *err)
{
    if (o->scene_path)
        return error_set(err, ST_USAGE, "more than one scene given: '%s' and '%s'", o->scene_path, a);
    o->scene_path = a;
    return ST_OK;
}

/* The value of flag `a` that takes one: `value` (after '=' or in the same word), else
 * the next argument (advancing *i). */
static Status option_take_value(const OptionSpec *s, const char *a, const char *value, int argc, char **argv, int *i,
                                Options *o, Error *err)
{
    if (!value && *i + 1 >= argc) return error_set(err, ST_USAGE, "%s needs a value", a);
    if (!value) value = argv[++*i];
    return option_set(s, a, value, o, err);
}

/* -qo FILE: one-letter flags bundled in one word, as getopt reads them. Switches may
 * follow each other; a flag that takes a value ends the bundle, its value the rest of
 * the word (-ofile.png) or the next argument. */
static Status options_parse_bundle(int argc, char **argv, int *i, Options *o, Error *err)
{
    const char *a = argv[*i];
    for (const char *p = a + 1; *p; p++) {
        char one[3] = { '-', *p, '\0' };
        const OptionSpec *s = option_find(one);
        if (!s && p == a + 1) return option_unknown(a, err);   /* not a bundle: "-spp" */
        if (!s) return error_set(err, ST_USAGE, "unknown option '%s' in '%s'", one, a);
        if (s->kind != OPTION_SWITCH) return option_take_value(s, one, p[1] ? p + 1 : NULL, argc, argv, i, o, err);
        Status st = option_set(s, one, NULL, o, err);
        if (st) return st;
    }
    return ST_OK;
}

/* argv[*i]: a flag (with its value, advancing *i past it), a bundle of short flags,
 * "--" (after which every argument is the scene's: *ended), or the scene. */
static Status options_parse_arg(int argc, char **argv, int *i, int *ended, Options *o, Error *err)
{
    const char *a = argv[*i];
    if (*ended || a[0] != '-' || a[1] == '\0') return options_scene(a, o, err);
    if (strcmp(a, "--") == 0) {
        *ended = 1;
        return ST_OK;
    }
    if (a[1] != '-' && a[2] != '\0') return options_parse_bundle(argc, argv, i, o, err);
    /* --flag=value is accepted too */
    char flag[64];
    const char *value = NULL;
    const char *eq = a[1] == '-' ? strchr(a, '=') : NULL;
    if (eq) {
        size_t n = (size_t)(eq - a);
        if (n >= sizeof flag) return option_unknown(a, err);
        memcpy(flag, a, n);
        flag[n] = '\0';
        value = eq + 1;
        a = flag;
    }
    const OptionSpec *s = option_find(a);
    if (!s) return option_unknown(a, err);
    if (s->kind == OPTION_SWITCH) return option_set(s, a, value, o, err);
    return option_take_value(s, a, value, argc, argv, i, o, err);
}

/* The viewer writes no output file of its own (C saves frames) and renders until it is
 * closed: the flags that shape a batch render's files and its end do not apply. */
static Status options_check_interactive(const Options *o, Error *err)
{
    if (!o->interactive) return ST_OK;
    const char *flag = o->output ? "--output" : o->checkpoint_path ? (o->resume_path ? "--resume" : "--checkpoint")
                     : o->time_limit > 0.0 ? "--time-limit" : o->progressive_seconds > 0.0 ? "--progressive-output"
                     : o->aovs ? "--aov" : o->adaptive > 0.0 ? "--adaptive"
                     : o->display_server ? "--display-server" : o->noise_threshold > 0.0 ? "--noise-threshold"
                     : o->range_end >= 0 ? "--sample-range" : o->stats == STATS_JSON ? "--stats=json"
                     : o->crop_kind == CROP_FRACTIONS ? "--crop" : o->crop_kind == CROP_PIXELS ? "--pixel-bounds"
                     : o->frames_first >= 0 ? "--frames" : NULL;
    if (flag)
        return error_set(err, ST_USAGE, "--interactive cannot be combined with %s (the viewer saves frames "
                                        "with the C key; see docs/viewer.md)", flag);
    return ST_OK;
}

/* -o - (or FORMAT:-) writes the image to standard output once, at the end: the flags
 * that write it again, or write images beside it, need a file. */
static Status options_check_stdout(const Options *o, Error *err)
{
    if (!o->output || !image_path_is_stdout(o->output)) return ST_OK;
    const char *flag = o->progressive_seconds > 0.0 ? "--progressive-output" : o->aovs ? "--aov"
                     : o->adaptive > 0.0 ? "--adaptive" : o->frames_first >= 0 ? "--frames" : NULL;
    if (flag)
        return error_set(err, ST_USAGE, "%s cannot be used with -o %s: standard output takes the image once, "
                         "and %s writes it again or beside it; name a file with -o", flag, o->output, flag);
    return ST_OK;
}

/* What depends on several flags. */
Status options_finish(Options *o, Error *err)
{
    if (o->checkpoint_seconds > 0.0 && !o->checkpoint_path && !o->resume_path)
        return error_set(err, ST_USAGE, "--checkpoint-interval needs --checkpoint FILE (or --resume FILE)");
    if (o->resume_path && !o->checkpoint_path) o->checkpoint_path = o->resume_path;
    if (o->range_end >= 0 && o->denoise && !o->checkpoint_path)
        return error_set(err, ST_USAGE, "--denoise with --sample-range keeps the denoiser's inputs in the part's "
                         "checkpoint for clpt merge --denoise: give --checkpoint PART");
    if (o->range_end >= 0 && o->adaptive > 0.0)
        return error_set(err, ST_USAGE, "--adaptive cannot be used with --sample-range (it needs the whole image)");
    /* Flags that shape what another flag turns on do nothing alone: said, not ignored
     * (an image rendered without the pass or the depth image the user asked for). */
    if (o->adaptive_spp && !(o->adaptive > 0.0))
        return error_set(err, ST_USAGE, "--adaptive-spp sets the samples of the adaptive pass, which --adaptive "
                         "THRESHOLD turns on; give both, or neither");
    if (!o->adaptive_spp) o->adaptive_spp = 16;
    if (o->min_spp && !(o->noise_threshold > 0.0))
        return error_set(err, ST_USAGE, "--min-spp sets the samples before --noise-threshold stops a pixel; give "
                         "both, or neither");
    if (!o->min_spp) o->min_spp = ADAPTIVE_DEFAULT_MIN_SPP;
    if (o->range_end >= 0 && o->noise_threshold > 0.0)
        return error_set(err, ST_USAGE, "--noise-threshold cannot be used with --sample-range (its decisions need "
                         "the whole render)");
    if (o->depth_near != o->depth_far && !(o->aovs & (1u << INTEGRATOR_AOV_DEPTH)))
        return error_set(err, ST_USAGE, "--depth-range scales the depth image, which --aov depth turns on; "
                         "give both, or neither");
    if (o->checkpoint_seconds <= 0.0) o->checkpoint_seconds = 60.0;
    if (o->fps > 0.0 && o->frames_first < 0)
        return error_set(err, ST_USAGE, "--fps sets the frame rate of --frames A:B; give both, or neither");
    if (!(o->fps > 0.0)) o->fps = 24.0;
    if (o->shutter_close > o->shutter_open && o->anim_time >= 0.0)
        return error_set(err, ST_USAGE, "--shutter blurs the animation over a time and --time poses it at one: "
                         "give one");
    if (o->shutter_close > o->shutter_open && o->frames_first >= 0)
        return error_set(err, ST_USAGE, "--shutter A:B opens once; with --frames give --shutter F, the fraction of "
                         "each frame's time it is open");
    if (o->shutter_fraction > 0.0 && o->frames_first < 0)
        return error_set(err, ST_USAGE, "--shutter F is a fraction of each frame's time, for --frames; for one "
                         "image give --shutter A:B in seconds");
    if (o->anim_time >= 0.0 && o->frames_first >= 0)
        return error_set(err, ST_USAGE, "--time poses the animation at one time and --frames at each frame's: give "
                         "one");
    if (o->frames_first >= 0 && o->range_end >= 0)
        return error_set(err, ST_USAGE, "--frames cannot be used with --sample-range (render each frame whole)");
    if (o->frames_first >= 0 && o->display_server)
        return error_set(err, ST_USAGE, "--frames cannot be used with --display-server (the live display shows one "
                         "image; open each frame's file instead)");
    if (!o->scene_path && !o->help && !o->version && !o->list_devices)
        return error_set(err, ST_USAGE, "no scene given (usage: clpt [options] SCENE)");
    Status st = options_check_stdout(o, err);
    return st ? st : options_check_interactive(o, err);
}

Status options_parse(int argc, char **argv, Options *o, Error *err)
{
    options_init(o);
    int first = 1;
    CourseStyle course = course_args_style(argc, argv);
    if (course != COURSE_NONE) {
        Status st = course_args_parse(course, argc, argv, o, &first, err);
        if (st) return st;
    }
    int ended = 0;
    for (int i = first; i < argc; i++) {
        Status st = options_parse_arg(argc, argv, &i, &ended, o, err);
        if (st) return st;
    }
    return options_finish(o, err);
}
