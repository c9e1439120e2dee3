/* course_args.h — the command lines of the courses' reference ray tracers, so that clpt
 * can stand in for them (docs/classic-format.md, "The course command lines"):
 *
 *   MIT 6.837:  clpt -size W H -input FILE -output FILE [-normals FILE]
 *                    [-depth NEAR FAR FILE] [-bounces N] [-shadows]
 *   Tsinghua:   clpt SCENE.txt OUT.bmp
 *
 * Each is translated into the Options of clpt's own flags that render what the course's
 * program renders. Kept apart from options.c: the course's syntax has nothing in common
 * with ours but the result. */
#ifndef CLPT_COURSE_ARGS_H
#define CLPT_COURSE_ARGS_H

#include "base/status.h"
#include "option_values.h"

typedef enum { COURSE_NONE = 0, COURSE_MIT, COURSE_TSINGHUA } CourseStyle;

/* Which command line argv is: MIT when its first argument is -size or -input,
 * Tsinghua when it is two arguments that are not options, the second an image name
 * (.bmp, .png or .ppm), else clpt's own. Either may be followed by clpt's own long
 * options (--device scalar, --quiet, ...), which apply on top. */
CourseStyle course_args_style(int argc, char **argv);

/* Fills o (already holding clpt's defaults) from a course command line of `style`;
 * *next is the index of the first of clpt's own options after it (argc if none). On
 * ST_USAGE err says what is wrong. */
Status course_args_parse(CourseStyle style, int argc, char **argv, Options *o, int *next, Error *err);

#endif /* CLPT_COURSE_ARGS_H */
