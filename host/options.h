/* options.h — the command line. options.c's OPTIONS list names every flag once: its
 * parsing, its line in --help and the choices its error messages list come from it. */
#ifndef CLPT_OPTIONS_H
#define CLPT_OPTIONS_H

#include <stddef.h>
#include <stdio.h>

#include "base/status.h"
#include "option_values.h"

/* How a flag's value is read. */
typedef enum {
    OPTION_SWITCH,   /* no value: sets an int to 1 */
    OPTION_TEXT,     /* a file, folder or device list, kept as given (not empty) */
    OPTION_LONG,     /* an integer in [lo, hi] into a long */
    OPTION_UINT,     /* the same into an unsigned */
    OPTION_INT,      /* the same into an int */
    OPTION_SECONDS,  /* a positive number of seconds into a double */
    OPTION_CHOICE,   /* one word of `choices` into an int */
    OPTION_CUSTOM,   /* read by its own function */
} OptionKind;

typedef struct {
    const char *name;
    int value;
} OptionChoice;

/* One flag of the list. */
typedef struct {
    const char *name, *alias;     /* "--output", "-o" (NULL: no short form) */
    OptionKind kind;
    const char *metavar;          /* its value in --help ("FILE"); NULL: a switch or a choice */
    size_t offset;                /* of its field in Options */
    long lo, hi;                  /* LONG, UINT, INT: the range */
    const char *what;             /* TEXT: what the value names ("file name") */
    const OptionChoice *choices;  /* CHOICE: ending with a NULL name */
    Status (*parse)(const char *v, Options *o, Error *err);   /* CUSTOM */
    int section;                  /* where --help lists it */
    const char *help;             /* its lines in --help, '\n' between them */
} OptionSpec;

/* Parses argv; on ST_USAGE err holds the message. --help and --version set flags and
 * succeed without a scene. */
Status options_parse(int argc, char **argv, Options *o, Error *err);
void options_print_help(FILE *f);
/* --help's sections, in order (the man page is written from them): the text of
 * section i, its heading (a line ending in ':') and any prose or table lines, is
 * followed in --help by the flags whose .section is i. The first holds the usage lines
 * and the description; NULL past the last. */
size_t options_help_sections(void);
const char *options_help_section(size_t i);
/* What follows the flag's name in --help (" FILE", " bvh|kdtree", "[=text|json]",
 * or "" for a switch), into buf. */
void option_value_text(const OptionSpec *s, char *buf, size_t size);

/* The library's settings (api/) are Options set one flag at a time, by the same table:
 * options_init gives the defaults of a command line without flags; options_set reads
 * `value` for the flag `name` ("spp" or "--spp"; a switch takes 1/on/true or
 * 0/off/false), keeping pointers into `value` for text flags; options_finish checks
 * what depends on several flags (o->scene_path set), as options_parse does last. */
void options_init(Options *o);
Status options_set(Options *o, const char *name, const char *value, Error *err);
Status options_finish(Options *o, Error *err);
/* The i-th flag of the list, NULL past the last (the tests, the man page and the shell
 * completions read the list through it). */
const OptionSpec *options_flag(size_t i);

/* Shared by options.c and options_parse.c: an integer in [lo, hi]; a positive number
 * of seconds (each value whole, no blank at either end); a choice's words joined by
 * '|' or, quoted, for a message ("'a', 'b' or 'c'"). */
Status option_parse_long(const char *flag, const char *s, long lo, long hi, long *out, Error *err);
Status option_parse_seconds(const char *flag, const char *s, double *out, Error *err);
void option_choices_text(const OptionChoice *c, int quoted, char *buf, size_t size);

#endif /* CLPT_OPTIONS_H */
