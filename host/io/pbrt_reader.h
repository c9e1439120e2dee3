/*
 * pbrt_reader.h — the parts of the pbrt-v4 reader (pbrt_parse.h) share this: the parser's
 * state, the parameter lists, and the functions one part calls in another. As pbrt-v4
 * separates parsing from building the scene, the reader is cut by concern:
 *   pbrt_parse.c     the directive loop, transforms, graphics state, camera/film options,
 *                    includes, the entry points
 *   pbrt_params.c    "type name" [values] parameter lists, spectra, positional arguments
 *   pbrt_material.c  materials and textures
 *   pbrt_light.c     area and other lights
 *   pbrt_shape.c     shapes: each type's reader, the Shape dispatch
 *   pbrt_object.c    object instancing, and shapes under a moving transform
 *   pbrt_medium.c    participating media and the shapes that bound them
 *   pbrt_volume.c    the media made into density grids: nanovdb files, cloud, rgbgrid
 * Not for use outside these files.
 */
#ifndef CLPT_PBRT_READER_H
#define CLPT_PBRT_READER_H

#include <stddef.h>

#include "base/strmap.h"
#include "io/lexer.h"
#include "io/reader.h"
#include "scene/media.h"
#include "scene/mesh_sink.h"
#include "scene/scene.h"
#include "scene/transform.h"

/* ------------------------------------------------------------------ parameter lists */

typedef enum {
    PT_FLOAT, PT_INTEGER, PT_BOOL, PT_STRING, PT_TEXTURE, PT_POINT2, PT_VECTOR2, PT_POINT3,
    PT_VECTOR3, PT_NORMAL, PT_RGB, PT_SPECTRUM, PT_BLACKBODY, PT_N
} PType;

typedef struct {
    PType type;
    Token decl;              /* the "type name" string, for positions */
    const char *name;        /* inside decl's text */
    size_t name_len;
    size_t first, n;         /* values: nums[first..] or strs[first..] */
    int strings;             /* the values are strings (string, texture, bool, named spectrum) */
    int used;
} Param;

typedef struct {
    Param *p;     size_t n, cap;
    double *nums; size_t n_nums, cap_nums;
    Token *strs;  size_t n_strs, cap_strs;
} ParamList;

/* ------------------------------------------------------------------ parser state */

/* pbrt-v4 keeps two current transforms, for the start and the end of TransformTimes
 * (docs/pbrt.md#motion); ActiveTransform picks which of them the transform directives
 * change. */
enum { PBRT_ACTIVE_START = 1, PBRT_ACTIVE_END = 2, PBRT_ACTIVE_ALL = 3 };

typedef struct {
    Transform ctm;           /* at the start time: the pose every still thing takes */
    Transform ctm_end;       /* at the end time (equal to ctm unless something moves) */
    int reverse;
    uint material;           /* NO_INDEX: pbrt's default (diffuse 0.5), made on first use */
    int area;                /* an AreaLightSource is active */
    vec3 area_L;
    int area_twosided;
    uint area_material;      /* material + emission, made on first use */
    int active;              /* PBRT_ACTIVE_*: the transforms the directives change */
    uint medium_in, medium_out;   /* MediumInterface: 0 vacuum, else 1 + a medium's index */
} GState;

typedef struct {
    const char *name;        /* a constant's value is `color`; else a scene texture */
    int constant;
    vec3 color;
    uint index;
    vec3 mean;               /* the texture's mean colour (a constant's is its colour):
                              * what stands in where only a constant fits */
} PTexture;

typedef struct {
    Transform start, end;
} PTransformPair;

/* A material named by NamedMaterial and not yet defined: where it was first used. */
typedef struct {
    uint index;
    int defined;
    char where[160];   /* "path:line:col: material 'name'" for the error at the end */
} PPending;

/* An ObjectBegin/End: a scene object its ObjectInstances place (docs/instancing.md),
 * or, when it holds no shapes, its shapes taken out of the scene and copied in at each
 * instance. An object with an emitting sphere keeps its shapes here too, for the
 * instances that copy them (a transform that is no similarity: pbrt_shape.c). */
typedef struct PMovingPart PMovingPart;

typedef struct {
    uint object;          /* the scene's object, or NO_INDEX: copies of the arrays below */
    int sphere_emits;     /* copy, rather than place, under a transform no similarity */
    Sphere *spheres;      size_t n_spheres;
    SphereXform *sphere_xforms;  size_t n_sphere_xforms;   /* Sphere.xform indexes this */
    Triangle *triangles;  size_t n_triangles;
    TriShading *shading;  size_t n_shading;   /* Triangle.shading indexes this */
    PMovingPart *moving;  size_t n_moving;    /* its Shapes under a moving transform */
} PObject;

/* A Shape inside ObjectBegin/End under a moving transform, which pbrt-v4 moves within
 * its object (docs/pbrt.md#motion): its shapes, made in their own space (both
 * transforms the identity), kept in `shapes` until ObjectEnd makes them an object of
 * their own (`object`, an index into Parser.objects), and the CTM's two transforms at
 * the Shape. Each ObjectInstance places that object as a moving instance under its own
 * transform times these. */
struct PMovingPart {
    PObject shapes;       /* until ObjectEnd: the shapes taken out of the object's */
    uint32_t object;      /* after it: Parser.objects' entry of its own object */
    Transform start, end;
    unsigned line, col;   /* the Shape's type, for messages */
};

typedef struct {
    Scene *s;
    Error *err;
    const char *top_path;    /* includes are found beside the main file, as pbrt does */
    int depth;
    int depth_exceeded;
    int world;               /* after WorldBegin */
    GState g;
    GState *stack;  size_t n_stack, cap_stack;
    StrMap named_material;   /* name -> material index */
    StrMap named_medium;     /* name -> 0 (a medium clpt leaves empty) or 1 + medium index */
    /* NamedMaterial before its MakeNamedMaterial (pbrt-v4 resolves names after the whole
     * file): a diffuse placeholder, replaced in place when the definition comes */
    PPending *pending;  size_t n_pending, cap_pending;
    /* area-light copies of a placeholder (material + emission), patched with it */
    struct { uint area, base; } *area_of_pending;  size_t n_area_pending, cap_area_pending;
    StrMap coordsys;         /* name -> index into coordsys_xf (a start and an end transform) */
    PTransformPair *coordsys_xf;  size_t n_coordsys, cap_coordsys;
    double time_start, time_end;  /* TransformTimes: the times of ctm and ctm_end (0 and 1) */
    StrMap tex_by_name;      /* name -> index into tex */
    PTexture *tex;  size_t n_tex, cap_tex;
    StrMap warned;           /* warning keys already given */
    StrMap object_by_name;   /* name -> index into objects */
    PObject *objects;  size_t n_objects, cap_objects;
    int in_object;           /* inside ObjectBegin: what it started with */
    size_t obj_spheres, obj_triangles, obj_shading, obj_stack, obj_sphere_xforms;
    size_t obj_first[OBJ_KINDS];   /* the scene's counts at ObjectBegin (scene_object_counts) */
    char obj_where[160];     /* "path:line:col" of the ObjectBegin, for an unclosed one */
    PMovingPart *obj_moving;  size_t n_obj_moving, cap_obj_moving;   /* its moving Shapes */
    size_t part_keys;        /* poses made for moving Shapes in objects (PBRT_MAX_PART_KEYS) */
    /* triangles made so far by tessellating what the file describes in a few numbers
     * (loopsubdiv, emitting ellipsoids): at most CLPT_MAX_TESSELLATED_TRIANGLES */
    size_t tessellated;
    Token obj_name;          /* its name, copied into obj_name_buf */
    char *obj_name_buf;
    ParamList pl;
    /* the camera, finished once the film's size is known */
    int have_camera, cam_ortho;
    Transform cam_from_world, cam_from_world_end;
    double cam_time_start, cam_time_end;   /* the TransformTimes when the Camera came */
    double fov, lens_radius, focal_distance, screen_half;
} Parser;

/* Gives a warning once per key ("Shape disk", "diffuse:foo"), at file:line. */
#define warn_once(p, lx, at, key, ...) reader_warn_once((p)->s, &(p)->warned, lx, at, key, (p)->err, __VA_ARGS__)

/* pbrt_params.c: parameter lists, spectra, positional arguments, helpers */
int pbrt_grow(void **ptr, size_t *cap, size_t need, size_t elem);
int pbrt_tok_double(const Token *t, double *out);
int pbrt_tok_is_bool(const Token *t);
int pbrt_tok_eq(const Token *t, const char *s);
Status pbrt_parse_params(Parser *p, Lexer *lx);
Param *pbrt_param_find(Parser *p, const char *name);
Status pbrt_param_type_error(Parser *p, const Lexer *lx, const Param *pa, const char *what);
Status pbrt_get_float(Parser *p, const Lexer *lx, const char *name, double *out);
Status pbrt_get_int(Parser *p, const Lexer *lx, const char *name, long *out);
Status pbrt_get_int_in(Parser *p, const Lexer *lx, const char *name, long lo, long hi, long *out);
Status pbrt_get_bool(Parser *p, const Lexer *lx, const char *name, int *out);
Status pbrt_get_string(Parser *p, const Lexer *lx, const char *name, const Token **out);
Status pbrt_get_point(Parser *p, const Lexer *lx, const char *name, vec3 *out);
Status pbrt_get_spectrum(Parser *p, const Lexer *lx, const char *name, vec3 *out, const PTexture **tex, int *given);
Status pbrt_get_float_tex(Parser *p, const Lexer *lx, const char *name, double *out);
Status pbrt_warn_unused(Parser *p, const Lexer *lx, const char *what);
Status pbrt_expect_string(Parser *p, Lexer *lx, const char *what, Token *t);
Status pbrt_expect_head(Parser *p, Lexer *lx, const char *what, Token *t);
Status pbrt_expect_defined(Parser *p, Lexer *lx, const StrMap *map, const char *what, const char *definer,
                           Token *name, uint32_t *index);
Status pbrt_expect_numbers(Parser *p, Lexer *lx, double *out, int n, const char *what);
char *pbrt_beside_main(const Parser *p, const Token *f);

/* The directive handlers declared below all take (Parser, Lexer, the directive's
 * token), the signature pbrt_parse.c's directive table calls: their declarations are
 * alike by design, one per entry of that table. Those whose head is one quoted type or
 * name (Material, Shape, LightSource, ...) also take that head, which the table's
 * dispatcher has read with its parameter list (pbrt_expect_head). */
/* pbrt_material.c: Material, MakeNamedMaterial, NamedMaterial, Texture */
Status pbrt_material(Parser *p, Lexer *lx, const Token *kw, const Token *type);
Status pbrt_make_named_material(Parser *p, Lexer *lx, const Token *kw, const Token *name);
Status pbrt_named_material(Parser *p, Lexer *lx, const Token *kw);
Status pbrt_texture(Parser *p, Lexer *lx, const Token *kw);
Status pbrt_shape_material(Parser *p, uint *out);

/* pbrt_light.c: AreaLightSource, LightSource */
Status pbrt_area_light(Parser *p, Lexer *lx, const Token *kw, const Token *type);
vec3 pbrt_xf_dir(const Transform *t, vec3 d);
Status pbrt_light(Parser *p, Lexer *lx, const Token *kw, const Token *type);

/* pbrt_shape.c: Shape */
Status pbrt_shape(Parser *p, Lexer *lx, const Token *kw, const Token *type);
/* A Shape of `type`, its parameters read, under the current transform's start pose. */
Status pbrt_shape_make(Parser *p, Lexer *lx, const Token *type);
/* Whether t is a similarity (a rotation, uniform scale and translation), and its scale. */
int pbrt_is_similarity(const Transform *t, double *scale);
/* A sphere of radius r under xf as a mesh of triangles (the kernels sample only round
 * sphere lights), counted against the scene's tessellation budget (`what` names it in
 * the message, at `at`), facing out, or in when `reverse`. */
Status pbrt_sphere_mesh(Parser *p, const Lexer *lx, const Token *at, const char *what, const Transform *xf, double r,
                        uint material, int reverse);

/* pbrt_object.c: ObjectBegin/End/Instance, a Shape under a moving transform (outside
 * an object, and inside one), and freeing the objects' copies at the end */
Status pbrt_shape_moving(Parser *p, Lexer *lx, const Token *kw, const Token *type);
Status pbrt_object_shape_moving(Parser *p, Lexer *lx, const Token *type);
void pbrt_objects_free(Parser *p);
Status pbrt_object_begin(Parser *p, Lexer *lx, const Token *kw);
Status pbrt_object_end(Parser *p, Lexer *lx, const Token *kw);
Status pbrt_object_instance(Parser *p, Lexer *lx, const Token *kw);

/* pbrt_medium.c: MakeNamedMedium, MediumInterface, the media a shape bounds */
Status pbrt_make_named_medium(Parser *p, Lexer *lx, const Token *kw);
Status pbrt_medium_interface(Parser *p, Lexer *lx, const Token *kw);
/* A medium's sigma_a and sigma_s (1 each by default, as pbrt-v4), times "scale" where
 * read_scale (the types that read it), and g: the coefficients per unit of density,
 * checked (scale in [0, 1e30], g in (-1, 1), a finite extinction). */
Status pbrt_medium_coefficients(Parser *p, const Lexer *lx, const Token *name, int read_scale, vec3 *sa, vec3 *ss,
                                float *g_out);
/* A grid's nx ny nz and their product, and its box p0 p1: checked as every grid medium
 * reads them (pbrt-v4's uniformgrid and rgbgrid). */
Status pbrt_medium_grid_size(Parser *p, const Lexer *lx, const Token *name, long n[3], double *cells);
Status pbrt_medium_box(Parser *p, const Lexer *lx, const Token *name, vec3 *lo, vec3 *hi);
/* How a temperature grid becomes kelvin: "temperatureoffset" (or pbrt-v4's older
 * "temperaturecutoff"; 0) and "temperaturescale" (1, >= 0), checked (uniformgrid, nanovdb). */
Status pbrt_medium_temperature(Parser *p, const Lexer *lx, GridTemperature *how);
/* A temperature grid's emission, sigma_a times `scale` (its largest Lescale) times a
 * blackbody's colour, checked to stay a float (the error names the medium). */
Status pbrt_medium_glow_check(Parser *p, const Lexer *lx, const Token *name, vec3 sa, double scale);
/* The material a shape of `material` gets in the current MediumInterface. */
Status pbrt_shape_media(Parser *p, uint material, uint *out);

/* pbrt_volume.c: media made into a density grid at load ("nanovdb", "cloud", "rgbgrid") */
int pbrt_volume_type(const Token *type);
Status pbrt_volume_medium(Parser *p, const Lexer *lx, const Token *name, const Token *type, Medium *out);
/* pbrt-v4's cloud density at a point of the medium's space, and the bake's grid size
 * for the box lo..hi (docs/media.md#clouds); for the tests. */
float pbrt_cloud_density(float x, float y, float z, float density, float wispiness, float frequency);
void pbrt_cloud_resolution(vec3 lo, vec3 hi, float frequency, unsigned n[3]);

/* pbrt_parse.c: directives, transforms, graphics state, files */
Status pbrt_push_state(Parser *p);
/* 1 when the current transform differs between the start and the end time: what it
 * places moves (pbrt-v4's CTMIsAnimated). */
int pbrt_ctm_moves(const Parser *p);
/* Warns once, at `at`, that `what` (a shape, a light, ...) under a moving transform is
 * placed at its start-time pose: only instances and the camera move in clpt. */
Status pbrt_warn_still(Parser *p, const Lexer *lx, const Token *at, const char *what);

#endif /* CLPT_PBRT_READER_H */
