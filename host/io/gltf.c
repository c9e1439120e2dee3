/* gltf.c — glTF 2.0 and GLB scenes (gltf.h). */
#include "io/gltf.h"

#include "base/bytes.h"
#include "base/limit.h"
#include "base/strmap.h"
#include "io/lexer.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "kmath.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cjson/cJSON.h>

#define GLB_MAGIC 0x46546C67u      /* "glTF" */
#define GLB_JSON 0x4E4F534Au       /* "JSON" */
#define GLB_BIN 0x004E4942u        /* "BIN\0" */
/* glTF lights are photometric (candela, lux); clpt's are radiometric: divided by the
 * luminous efficacy of 555 nm light, 683 lm/W (docs/gltf.md). */
#define LUMENS_PER_WATT 683.0
/* Triangles one file may make, nodes times primitives included: a small file that
 * instances a large mesh many times must not exhaust memory (each triangle costs clpt
 * a few hundred bytes with its shading record and kd-tree), so the count is bounded by
 * the input's size, and absolutely. A real file's mesh data takes 20 bytes or more per
 * triangle, so one per byte still lets each be instanced some 20 times; 16 per byte
 * let a 4 MB strip of 1-byte indices, instanced, make 2^26 triangles (issue 39). */
#define GLTF_TRIANGLES_PER_BYTE 1u
#define GLTF_MAX_TRIANGLES ((size_t)1 << 26)

typedef struct {
    const unsigned char *p;
    size_t len;
    size_t whole;         /* the bytes of the data before a buffer's byteLength cut them */
    char *owned;          /* heap copy (external file, decoded data: URI), or NULL */
} Buf;

/* The top-level arrays (and the lights of KHR_lights_punctual) as arrays of pointers:
 * cJSON keeps arrays as linked lists, where finding item i walks i items, and a reader
 * that looked every index up that way would be quadratic in its input. */
enum { T_BUFFERS, T_VIEWS, T_ACCESSORS, T_MESHES, T_MATERIALS, T_TEXTURES, T_IMAGES, T_SAMPLERS, T_CAMERAS, T_NODES,
       T_SCENES, T_LIGHTS, T_N };
static const char *const table_names[T_N] = { "buffers", "bufferViews", "accessors", "meshes", "materials",
                                              "textures", "images", "samplers", "cameras", "nodes", "scenes",
                                              "lights" };
typedef struct {
    const cJSON **item;
    int n;
} Table;

typedef struct {
    const char *path;
    Scene *s;
    Error *err;
    const MeshOptions *o;
    GltfView *view;
    cJSON *root;
    const unsigned char *bin;  size_t bin_len;   /* the GLB's BIN chunk */
    Buf *bufs;        int n_bufs;
    StrMap buffer_files;             /* resolved file name -> the first buffer read from it */
    int reading_buffer;              /* the buffer uri_read reads for, or -1 (an image) */
    StrMap image_sources[2];         /* an image's source -> its scene texture, sRGB [0] and linear [1] */
    uint *mats;       int n_mats;      /* scene material per glTF material, or NO_INDEX */
    uint default_mat;
    uint *tex;        int n_images;    /* per image: sRGB [2i], linear [2i+1] texture */
    unsigned char *visited;  int n_nodes;
    size_t triangles, max_triangles;
    int has_lights;
    Table t[T_N];
} Gltf;

/* ------------------------------------------------------------------ JSON helpers */

static Status bad(Gltf *g, const char *jpath, const char *what)
{
    return error_set(g->err, ST_INPUT, "%s: %s: %s", g->path, jpath, what);
}

static int count_of(const cJSON *a) { return cJSON_IsArray(a) ? cJSON_GetArraySize(a) : 0; }

/* The first element of an array (walk on with ->next), or NULL. */
static const cJSON *first_of(const cJSON *a) { return cJSON_IsArray(a) ? a->child : NULL; }

static const Table *table_of(const Gltf *g, const char *array)
{
    for (int i = 0; i < T_N; i++)
        if (strcmp(table_names[i], array) == 0) return &g->t[i];
    return &g->t[T_N - 1];   /* not reached: every caller names a table */
}

/* The integer at obj.key in [lo, hi], or def when absent (def < lo: required). */
static Status get_int(Gltf *g, const cJSON *obj, const char *key, long long def, long long lo, long long hi,
                      const char *jpath, long long *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        if (def < lo)
            return error_set(g->err, ST_INPUT, "%s: %s.%s: missing (required)", g->path, jpath, key);
        *out = def;
        return ST_OK;
    }
    double d = cJSON_IsNumber(v) ? v->valuedouble : NAN;
    if (!(d >= (double)lo && d <= (double)hi) || d != floor(d))
        return error_set(g->err, ST_INPUT, "%s: %s.%s: expected an integer from %lld to %lld", g->path, jpath, key,
                         lo, hi);
    *out = (long long)d;
    return ST_OK;
}

/* An index into the top-level array `array`. */
static Status get_index(Gltf *g, const cJSON *obj, const char *key, int required, const char *array,
                        const char *jpath, int *out)
{
    long long n = table_of(g, array)->n, v;
    const cJSON *item = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!item && !required) {
        *out = -1;
        return ST_OK;
    }
    if (item && cJSON_IsNumber(item) && (item->valuedouble < 0 || item->valuedouble >= (double)n) &&
        item->valuedouble == floor(item->valuedouble))
        return error_set(g->err, ST_INPUT, "%s: %s.%s: %s[%.0f] does not exist (the file has %lld)", g->path, jpath,
                         key, array, item->valuedouble, n);
    Status st = get_int(g, obj, key, -1, 0, n - 1, jpath, &v);
    if (st) return st;
    *out = (int)v;
    return ST_OK;
}

static Status get_num(Gltf *g, const cJSON *obj, const char *key, double def, double lo, double hi,
                      const char *jpath, double *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!v) {
        *out = def;
        return ST_OK;
    }
    if (!cJSON_IsNumber(v) || !(v->valuedouble >= lo && v->valuedouble <= hi))
        return error_set(g->err, ST_INPUT, "%s: %s.%s: expected a number from %g to %g", g->path, jpath, key, lo, hi);
    *out = v->valuedouble;
    return ST_OK;
}

/* n numbers at obj.key (def when absent). */
static Status get_nums(Gltf *g, const cJSON *obj, const char *key, int n, const double *def, const char *jpath,
                       double *out)
{
    const cJSON *a = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!a) {
        memcpy(out, def, (size_t)n * sizeof *out);
        return ST_OK;
    }
    if (count_of(a) != n)
        return error_set(g->err, ST_INPUT, "%s: %s.%s: expected an array of %d numbers", g->path, jpath, key, n);
    for (int i = 0; i < n; i++) {
        const cJSON *v = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(v) || !isfinite(v->valuedouble))
            return error_set(g->err, ST_INPUT, "%s: %s.%s[%d]: expected a finite number", g->path, jpath, key, i);
        out[i] = v->valuedouble;
    }
    return ST_OK;
}

static const cJSON *ext_of(const cJSON *obj, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(obj, "extensions"), name);
}

static const cJSON *item_at(const Gltf *g, const char *array, int i)
{
    const Table *t = table_of(g, array);
    return i >= 0 && i < t->n ? t->item[i] : NULL;
}

static Status table_build(Gltf *g, Table *t, const cJSON *a)
{
    t->n = count_of(a);
    t->item = malloc(((size_t)t->n + 1) * sizeof *t->item);
    if (!t->item) return error_set(g->err, ST_INTERNAL, "out of memory");
    int i = 0;
    for (const cJSON *c = first_of(a); c; c = c->next) t->item[i++] = c;
    return ST_OK;
}

static Status tables_build(Gltf *g)
{
    for (int i = 0; i < T_N; i++) {
        const cJSON *a = i == T_LIGHTS ? cJSON_GetObjectItemCaseSensitive(
                                             ext_of(g->root, "KHR_lights_punctual"), "lights")
                                       : cJSON_GetObjectItemCaseSensitive(g->root, table_names[i]);
        Status st = table_build(g, &g->t[i], a);
        if (st) return st;
    }
    return ST_OK;
}


/* ------------------------------------------------------------------ buffers */

static int b64_value(unsigned char c)
{
    if (c >= 'A' && c <= 'Z') return c - 'A';
    if (c >= 'a' && c <= 'z') return c - 'a' + 26;
    if (c >= '0' && c <= '9') return c - '0' + 52;
    if (c == '+' || c == '-') return 62;
    if (c == '/' || c == '_') return 63;
    return -1;
}

/* Decodes base64 text (padding optional) into a new heap buffer. */
static Status b64_decode(Gltf *g, const char *jpath, const char *text, Buf *out)
{
    size_t n = strlen(text);
    char *o = malloc(n / 4 * 3 + 3);
    if (!o) return error_set(g->err, ST_INTERNAL, "out of memory");
    size_t len = 0;
    uint32_t acc = 0;
    int bits = 0;
    for (size_t i = 0; i < n; i++) {
        if (text[i] == '=') break;
        int v = b64_value((unsigned char)text[i]);
        if (v < 0) {
            free(o);
            return error_set(g->err, ST_INPUT, "%s: %s: the data: URI has a character that is not base64 at %zu",
                             g->path, jpath, i);
        }
        acc = acc << 6 | (uint32_t)v;
        if ((bits += 6) >= 8) {
            bits -= 8;
            o[len++] = (char)(acc >> bits & 0xff);
        }
    }
    out->owned = o;
    out->p = (const unsigned char *)o;
    out->len = out->whole = len;
    return ST_OK;
}

/* The length of the scheme uri starts with (RFC 3986: a letter, then letters, digits,
 * '+', '-' or '.', then ':'), or 0 when it has none. */
static size_t uri_scheme_length(const char *uri)
{
    size_t i = 0;
    if (!((uri[0] >= 'a' && uri[0] <= 'z') || (uri[0] >= 'A' && uri[0] <= 'Z'))) return 0;
    while ((uri[i] >= 'a' && uri[i] <= 'z') || (uri[i] >= 'A' && uri[i] <= 'Z') || (uri[i] >= '0' && uri[i] <= '9') ||
           uri[i] == '+' || uri[i] == '-' || uri[i] == '.')
        i++;
    return uri[i] == ':' ? i : 0;
}

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* The file a uri other than a data: URI names (*file, freed with free). glTF 2.0 takes
 * URIs as RFC 3986 has them: a relative reference, resolved against the glTF file's
 * folder, with its percent-encoded bytes decoded ("wood%20floor.png" names "wood
 * floor.png"). It may leave that folder ("../textures/wood.png", as assets that share
 * textures do, and other viewers read): a scene names files anywhere anyway. Refused:
 * a scheme (clpt reads no http: or file:; a Windows drive letter reads as one), an
 * absolute path, before decoding or after, a '%' without two hex digits after it, and
 * %00 (a file name cannot hold a NUL). */
static Status uri_file(Gltf *g, const char *uri, const char *jpath, char **file)
{
    *file = NULL;
    size_t scheme = uri_scheme_length(uri);
    if (scheme)
        return error_set(g->err, ST_INPUT, "%s: %s: the URI's scheme '%.*s:' is not read (clpt reads data: URIs and "
                         "file names relative to the glTF file)", g->path, jpath, (int)(scheme > 20 ? 20 : scheme),
                         uri);
    size_t n = strlen(uri), len = 0;
    char *name = malloc(n + 1);
    if (!name) return error_set(g->err, ST_INTERNAL, "out of memory");
    for (size_t i = 0; i < n; i++) {
        if (uri[i] != '%') {
            name[len++] = uri[i];
            continue;
        }
        int hi = i + 2 < n + 1 ? hex_digit(uri[i + 1]) : -1, lo = hi >= 0 ? hex_digit(uri[i + 2]) : -1;
        if (hi < 0 || lo < 0 || (hi == 0 && lo == 0)) {
            free(name);
            return error_set(g->err, ST_INPUT, "%s: %s: character %zu of the URI: %s", g->path, jpath, i + 1,
                             hi == 0 && lo == 0 ? "%00, a NUL, cannot be part of a file name"
                                                : "'%' not followed by two hex digits (a percent-encoded byte)");
        }
        name[len++] = (char)(hi << 4 | lo);
        i += 2;
    }
    name[len] = '\0';
    if (name[0] == '/') {
        free(name);
        return bad(g, jpath, "an absolute path (clpt reads data: URIs and file names relative to the glTF file)");
    }
    path_resolve(g->path, name, len, PATH_BESIDE, file);
    free(name);
    return *file ? ST_OK : error_set(g->err, ST_INTERNAL, "out of memory");
}

/* The bytes a `uri` names: a data: URI (base64) or a relative file beside the glTF. */
static Status uri_read(Gltf *g, const char *uri, const char *jpath, Buf *out)
{
    if (strncmp(uri, "data:", 5) == 0) {
        const char *b64 = strstr(uri, ";base64,");
        if (!b64) return bad(g, jpath, "a data: URI that is not base64");
        return b64_decode(g, jpath, b64 + 8, out);
    }
    char *file;
    Status st = uri_file(g, uri, jpath, &file);
    if (st) return st;
    /* buffers that name one file share one read of it (a small file naming a large one
     * from many buffers read it once per buffer) */
    uint32_t first;
    if (strmap_find(&g->buffer_files, file, strlen(file), &first)) {
        free(file);
        out->p = g->bufs[first].p;
        out->len = out->whole = g->bufs[first].whole;
        out->owned = NULL;
        return ST_OK;
    }
    char *data;
    size_t len;
    st = lex_read_file(file, &data, &len, g->err);
    if (st) {
        free(file);
        reader_annotate_json(g->path, jpath, g->err);
        return st;
    }
    out->owned = data;
    out->p = (const unsigned char *)data;
    out->len = out->whole = len;
    int added = g->reading_buffer >= 0 ? strmap_add(&g->buffer_files, file, strlen(file), (uint32_t)g->reading_buffer)
                                       : 0;
    free(file);
    return added < 0 ? error_set(g->err, ST_INTERNAL, "out of memory") : ST_OK;
}

static Status buffers_load(Gltf *g)
{
    g->n_bufs = g->t[T_BUFFERS].n;
    g->bufs = calloc((size_t)g->n_bufs + 1, sizeof *g->bufs);
    if (!g->bufs) return error_set(g->err, ST_INTERNAL, "out of memory");
    for (int i = 0; i < g->n_bufs; i++) {
        char jp[64];
        snprintf(jp, sizeof jp, "buffers[%d]", i);
        const cJSON *b = g->t[T_BUFFERS].item[i];
        long long length;
        Status st = get_int(g, b, "byteLength", -1, 1, (long long)CLPT_MAX_FILE_BYTES, jp, &length);
        if (st) return st;
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
        Buf *f = &g->bufs[i];
        if (uri) {
            if (!cJSON_IsString(uri)) return bad(g, jp, "uri: expected a string");
            char jpu[80];
            snprintf(jpu, sizeof jpu, "%s.uri", jp);
            g->reading_buffer = i;
            st = uri_read(g, uri->valuestring, jpu, f);
            g->reading_buffer = -1;
            if (st) return st;
        } else if (i == 0 && g->bin) {
            f->p = g->bin;
            f->len = f->whole = g->bin_len;
        } else {
            return bad(g, jp, "no uri, and it is not the GLB's BIN chunk");
        }
        if ((unsigned long long)length > f->len)
            return error_set(g->err, ST_INPUT, "%s: %s: byteLength is %lld but the data has %zu bytes", g->path, jp,
                             length, f->len);
        f->len = (size_t)length;
    }
    return ST_OK;
}

/* The bytes of bufferViews[v] and its byteStride (0 when not given). */
static Status view_bytes(Gltf *g, int v, Buf *out, size_t *stride)
{
    char jp[64];
    snprintf(jp, sizeof jp, "bufferViews[%d]", v);
    const cJSON *bv = item_at(g, "bufferViews", v);
    int b;
    long long off, len, st_;
    Status st = get_index(g, bv, "buffer", 1, "buffers", jp, &b);
    if (!st) st = get_int(g, bv, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jp, &off);
    if (!st) st = get_int(g, bv, "byteLength", -1, 1, (long long)CLPT_MAX_FILE_BYTES, jp, &len);
    if (!st) st = get_int(g, bv, "byteStride", 0, 0, 252, jp, &st_);
    if (st) return st;
    const Buf *f = &g->bufs[b];
    if ((unsigned long long)(off + len) > f->len)
        return error_set(g->err, ST_INPUT, "%s: %s: bytes %lld..%lld are beyond buffers[%d], which has %zu", g->path,
                         jp, off, off + len, b, f->len);
    out->p = f->p + off;
    out->len = out->whole = (size_t)len;
    out->owned = NULL;
    *stride = (size_t)st_;
    return ST_OK;
}

/* ------------------------------------------------------------------ accessors */

static int comp_size(long long type)
{
    switch (type) {
    case 5120: case 5121: return 1;
    case 5122: case 5123: return 2;
    case 5125: case 5126: return 4;
    default: return 0;
    }
}

static double comp_read(const unsigned char *p, long long type, int normalized)
{
    switch (type) {
    case 5120: { double c = (int8_t)p[0]; return normalized ? fmax(c / 127.0, -1.0) : c; }
    case 5121: return normalized ? p[0] / 255.0 : p[0];
    case 5122: { double c = (int16_t)bytes_get_le16(p); return normalized ? fmax(c / 32767.0, -1.0) : c; }
    case 5123: { double c = bytes_get_le16(p); return normalized ? c / 65535.0 : c; }
    case 5125: { double c = (double)bytes_get_le32(p); return normalized ? c / 4294967295.0 : c; }
    default: {
        uint32_t u = bytes_get_le32(p);
        float f;
        memcpy(&f, &u, sizeof f);
        return f;
    }
    }
}

static int type_width(const char *t)
{
    static const char *const names[] = { "SCALAR", "VEC2", "VEC3", "VEC4" };
    for (int i = 0; i < 4; i++)
        if (strcmp(t, names[i]) == 0) return i + 1;
    return 0;
}

/* Sparse substitution: sparse.count (index, value) pairs replace elements. */
static Status acc_sparse(Gltf *g, const cJSON *sp, const char *jpath, long long count, int width, long long ctype,
                         int normalized, double *out)
{
    char jp[260];
    snprintf(jp, sizeof jp, "%s.sparse", jpath);
    long long n, ioff, voff, itype;
    const cJSON *ix = cJSON_GetObjectItemCaseSensitive(sp, "indices");
    const cJSON *vx = cJSON_GetObjectItemCaseSensitive(sp, "values");
    if (!cJSON_IsObject(ix) || !cJSON_IsObject(vx)) return bad(g, jp, "needs indices and values objects");
    int iview, vview;
    Status st = get_int(g, sp, "count", -1, 1, count, jp, &n);
    char jpi[300], jpv[300];
    snprintf(jpi, sizeof jpi, "%s.indices", jp);
    snprintf(jpv, sizeof jpv, "%s.values", jp);
    if (!st) st = get_index(g, ix, "bufferView", 1, "bufferViews", jpi, &iview);
    if (!st) st = get_int(g, ix, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jpi, &ioff);
    if (!st) st = get_int(g, ix, "componentType", -1, 5121, 5125, jpi, &itype);
    if (!st) st = get_index(g, vx, "bufferView", 1, "bufferViews", jpv, &vview);
    if (!st) st = get_int(g, vx, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jpv, &voff);
    if (st) return st;
    if (itype != 5121 && itype != 5123 && itype != 5125)
        return bad(g, jpi, "componentType must be 5121, 5123 or 5125");
    Buf ib, vb;
    size_t stride;
    if ((st = view_bytes(g, iview, &ib, &stride)) || (st = view_bytes(g, vview, &vb, &stride))) return st;
    uint64_t isz = (uint64_t)comp_size(itype), vsz = (uint64_t)comp_size(ctype) * (uint64_t)width;
    if ((uint64_t)ioff + (uint64_t)n * isz > ib.len)
        return error_set(g->err, ST_INPUT, "%s: %s: reads bytes %lld..%llu of bufferView %d, which has %zu", g->path,
                         jpi, ioff, (unsigned long long)((uint64_t)ioff + (uint64_t)n * isz), iview, ib.len);
    if ((uint64_t)voff + (uint64_t)n * vsz > vb.len)
        return error_set(g->err, ST_INPUT, "%s: %s: reads bytes %lld..%llu of bufferView %d, which has %zu", g->path,
                         jpv, voff, (unsigned long long)((uint64_t)voff + (uint64_t)n * vsz), vview, vb.len);
    for (long long i = 0; i < n; i++) {
        double e = comp_read(ib.p + ioff + (uint64_t)i * isz, itype, 0);
        if (e >= (double)count)
            return error_set(g->err, ST_INPUT, "%s: %s: index %lld is %.0f, past the accessor's %lld elements",
                             g->path, jpi, i, e, count);
        for (int c = 0; c < width; c++)
            out[(size_t)e * (size_t)width + (size_t)c] =
                comp_read(vb.p + voff + (uint64_t)i * vsz + (uint64_t)c * (uint64_t)comp_size(ctype), ctype,
                          normalized);
    }
    return ST_OK;
}

static Status acc_read_either(Gltf *g, int a, int width, int width2, const char *use, double **out, size_t *count,
                              int *got);

/* accessors[a] as `width`-wide elements of doubles (*out, *count elements), read for
 * the JSON path `use`. */
static Status acc_read(Gltf *g, int a, int width, const char *use, double **out, size_t *count)
{
    int got;
    return acc_read_either(g, a, width, 0, use, out, count, &got);
}

/* acc_read of an accessor that may be `width` or `width2` wide (0: only width); *got
 * says which. */
static Status acc_read_either(Gltf *g, int a, int width, int width2, const char *use, double **out, size_t *count,
                              int *got)
{
    char jp[200];
    snprintf(jp, sizeof jp, "%s: accessor %d", use, a);
    const cJSON *acc = item_at(g, "accessors", a);
    long long ctype, n, off;
    int view;
    Status st = get_int(g, acc, "componentType", -1, 5120, 5126, jp, &ctype);
    if (!st) st = get_int(g, acc, "count", -1, 1, (long long)CLPT_MAX_FILE_BYTES, jp, &n);
    if (!st) st = get_int(g, acc, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jp, &off);
    if (!st) st = get_index(g, acc, "bufferView", 0, "bufferViews", jp, &view);
    if (st) return st;
    if (!comp_size(ctype)) return bad(g, jp, "componentType is not one glTF defines");
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(acc, "type");
    int tw = cJSON_IsString(type) ? type_width(type->valuestring) : 0;
    if (tw != width && (!width2 || tw != width2)) {
        static const char *const names[] = { "SCALAR", "VEC2", "VEC3", "VEC4" };
        char what[80];
        if (width2)
            snprintf(what, sizeof what, "type must be %s or %s here", names[width - 1], names[width2 - 1]);
        else
            snprintf(what, sizeof what, "type must be %s here", names[width - 1]);
        return bad(g, jp, what);
    }
    width = tw;
    *got = tw;
    int normalized = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(acc, "normalized"));
    const cJSON *sparse = cJSON_GetObjectItemCaseSensitive(acc, "sparse");
    uint64_t esz = (uint64_t)comp_size(ctype) * (uint64_t)width;
    Buf vb = { NULL, 0, 0, NULL };
    size_t stride = 0;
    if (view >= 0) {
        if ((st = view_bytes(g, view, &vb, &stride))) return st;
        if (stride && stride < esz)
            return error_set(g->err, ST_INPUT, "%s: %s: byteStride %zu of bufferView %d is less than an element's "
                             "%llu bytes", g->path, jp, stride, view, (unsigned long long)esz);
        if (!stride) stride = (size_t)esz;
        uint64_t end = (uint64_t)off + (uint64_t)(n - 1) * stride + esz;
        if (end > vb.len)
            return error_set(g->err, ST_INPUT, "%s: %s reads bytes %lld..%llu of bufferView %d, which has %zu",
                             g->path, jp, off, (unsigned long long)end, view, vb.len);
    } else {
        /* all zeros but for a sparse part: its size is not bounded by any data, so by
         * the file's total buffer bytes (the reader stays linear in its input) */
        size_t total = 0;
        for (int i = 0; i < g->n_bufs; i++) total += g->bufs[i].len;
        if (!sparse) return bad(g, jp, "has neither a bufferView nor sparse values");
        if ((uint64_t)n > total + 65536)
            return error_set(g->err, ST_INPUT, "%s: %s: %lld elements without a bufferView is more than the file's "
                             "data can describe", g->path, jp, n);
    }
    double *d = calloc((size_t)n * (size_t)width, sizeof *d);
    if (!d) return error_set(g->err, ST_INTERNAL, "out of memory reading %s", jp);
    if (view >= 0)
        for (long long i = 0; i < n; i++)
            for (int c = 0; c < width; c++)
                d[(size_t)i * (size_t)width + (size_t)c] =
                    comp_read(vb.p + off + (uint64_t)i * stride + (uint64_t)c * (uint64_t)comp_size(ctype), ctype,
                              normalized);
    if (sparse && (st = acc_sparse(g, sparse, jp, n, width, ctype, normalized, d))) {
        free(d);
        return st;
    }
    *out = d;
    *count = (size_t)n;
    return ST_OK;
}

/* ------------------------------------------------------------------ materials */

/* The scene texture of textures[t] in the given encoding, read once. */
static Status texture_get(Gltf *g, int t, int linear, const char *jpath, uint *out)
{
    const cJSON *tex = item_at(g, "textures", t);
    char jp[64];
    snprintf(jp, sizeof jp, "textures[%d]", t);
    int img;
    Status st = get_index(g, tex, "source", 1, "images", jp, &img);
    if (st) return st;
    uint *slot = &g->tex[2 * img + (linear ? 1 : 0)];
    if (*slot != NO_INDEX) {
        *out = *slot;
        return ST_OK;
    }
    const cJSON *im = item_at(g, "images", img);
    char ji[64], src[1200];
    snprintf(ji, sizeof ji, "images[%d]", img);
    snprintf(src, sizeof src, "%s: %s (for %s)", g->path, ji, jpath);
    const cJSON *uri = cJSON_GetObjectItemCaseSensitive(im, "uri");
    int view;
    if ((st = get_index(g, im, "bufferView", 0, "bufferViews", ji, &view))) return st;
    /* images with one source (a file, a data: URI, a buffer view) share one decode of
     * it: a 20 KB GLB whose hundreds of images named one buffer view decoded it for each,
     * 2.1 GB in all (issue 39) */
    char *file = NULL;
    if (cJSON_IsString(uri) && strncmp(uri->valuestring, "data:", 5) != 0 &&
        (st = uri_file(g, uri->valuestring, ji, &file)))
        return st;
    /* a buffer view's key starts with a NUL, which no file name or URI holds */
    char view_key[24] = { 0 };
    size_t key_len = 1 + (size_t)snprintf(view_key + 1, sizeof view_key - 1, "view %d", view);
    const char *key = view_key;
    if (file || cJSON_IsString(uri)) {
        key = file ? file : uri->valuestring;
        key_len = strlen(key);
    }
    StrMap *known = &g->image_sources[linear ? 1 : 0];
    uint32_t shared;
    if ((cJSON_IsString(uri) || view >= 0) && strmap_find(known, key, key_len, &shared)) {
        free(file);
        *slot = *out = shared;
        return ST_OK;
    }
    if (file) {
        st = texture_load_image(g->s, NULL, file, linear, 0, slot, g->err);
        if (st) reader_annotate_json(g->path, ji, g->err);
    } else if (cJSON_IsString(uri)) {
        Buf b = { NULL, 0, 0, NULL };
        if (!(st = uri_read(g, uri->valuestring, ji, &b)))
            st = texture_load_image_memory(g->s, NULL, src, b.p, b.len, linear, slot, g->err);
        free(b.owned);
    } else if (view >= 0) {
        Buf b;
        size_t stride;
        if (!(st = view_bytes(g, view, &b, &stride)))
            st = texture_load_image_memory(g->s, NULL, src, b.p, b.len, linear, slot, g->err);
    } else {
        return bad(g, ji, "has neither a uri nor a bufferView");
    }
    if (!st && strmap_add(known, key, key_len, *slot) < 0) st = error_set(g->err, ST_INTERNAL, "out of memory");
    free(file);
    if (!st) *out = *slot;
    return st;
}

/* KHR_texture_transform's map: glTF's uv' = T R S uv, its rotation matrix
 * [cos -sin; sin cos] as the extension's shader writes it, taken between clpt's (u, v)
 * and glTF's (u, 1 - v) on both sides; its texCoord, when it has one, replaces *tc. */
static Status texture_transform(Gltf *g, const cJSON *tt, const char *jpath, float m[12], long long *tc)
{
    char jp[340];
    snprintf(jp, sizeof jp, "%s.extensions.KHR_texture_transform", jpath);
    static const double zero2[2] = { 0, 0 }, one2[2] = { 1, 1 };
    double off[2], sc[2], rot;
    Status st = get_nums(g, tt, "offset", 2, zero2, jp, off);
    if (!st) st = get_nums(g, tt, "scale", 2, one2, jp, sc);
    if (!st) st = get_num(g, tt, "rotation", 0.0, -1e6, 1e6, jp, &rot);
    if (!st) st = get_int(g, tt, "texCoord", *tc, 0, 64, jp, tc);
    if (st) return st;
    double a = sc[0] * cos(rot), b = -sc[1] * sin(rot), c = sc[0] * sin(rot), d = sc[1] * cos(rot);
    const float mm[12] = { (float)a, (float)-b, 0.0f, (float)(b + off[0]),
                           (float)-c, (float)d, 0.0f, (float)(1.0 - d - off[1]),
                           0.0f, 0.0f, 1.0f, 0.0f };
    memcpy(m, mm, sizeof mm);
    Texture t;
    memcpy(t.m, mm, sizeof mm);
    st = texture_check_map(&t, g->err);
    if (st) reader_annotate_json(g->path, jp, g->err);
    return st;
}

/* One axis of a sampler: glTF's REPEAT, CLAMP_TO_EDGE or MIRRORED_REPEAT. */
static Status sampler_wrap(Gltf *g, const cJSON *smp, const char *key, const char *jp, uint clamp, uint mirror,
                           uint *flags)
{
    long long w;
    Status st = get_int(g, smp, key, 10497, 0, 65535, jp, &w);
    if (st) return st;
    if (w == 33071) *flags |= clamp;
    else if (w == 33648) *flags |= mirror;
    else if (w != 10497)
        return error_set(g->err, ST_INPUT, "%s: %s.%s: expected 10497 (REPEAT), 33071 (CLAMP_TO_EDGE) or 33648 "
                         "(MIRRORED_REPEAT)", g->path, jp, key);
    return ST_OK;
}

/* The TEX_* sampling flags of textures[t]'s sampler: wrapS (u) and wrapT (v), and
 * magFilter NEAREST. clpt has no mip-maps, so one filter serves every lookup: the
 * magnification filter's; minFilter is ignored. */
static Status sampler_flags(Gltf *g, int t, uint *flags)
{
    *flags = 0;
    char jt[64];
    snprintf(jt, sizeof jt, "textures[%d]", t);
    int si;
    Status st = get_index(g, item_at(g, "textures", t), "sampler", 0, "samplers", jt, &si);
    if (st || si < 0) return st;
    const cJSON *smp = item_at(g, "samplers", si);
    char jp[64];
    snprintf(jp, sizeof jp, "samplers[%d]", si);
    long long mag;
    if ((st = sampler_wrap(g, smp, "wrapS", jp, TEX_CLAMP_U, TEX_MIRROR_U, flags)) ||
        (st = sampler_wrap(g, smp, "wrapT", jp, TEX_CLAMP_V, TEX_MIRROR_V, flags)) ||
        (st = get_int(g, smp, "magFilter", 9729, 0, 65535, jp, &mag)))
        return st;
    if (mag == 9728) *flags |= TEX_NEAREST;
    else if (mag != 9729)
        return error_set(g->err, ST_INPUT, "%s: %s.magFilter: expected 9728 (NEAREST) or 9729 (LINEAR)", g->path, jp);
    return ST_OK;
}

/* The texture a textureInfo object at obj.key names, or NO_INDEX: the image's texture,
 * or a copy of it (a texture record of its own over the same texels) with its sampler's
 * wrap and filter flags, TEX_UV1 for texCoord 1 and KHR_texture_transform's map. */
static Status texinfo(Gltf *g, const cJSON *obj, const char *key, int linear, const char *jpath, uint *out,
                      double *scale)
{
    const cJSON *ti = cJSON_GetObjectItemCaseSensitive(obj, key);
    *out = NO_INDEX;
    if (!ti) return ST_OK;
    char jp[300];
    snprintf(jp, sizeof jp, "%s.%s", jpath, key);
    int t;
    long long tc;
    uint flags;
    float m[12];
    const cJSON *tt = ext_of(ti, "KHR_texture_transform");
    Status st = get_index(g, ti, "index", 1, "textures", jp, &t);
    if (!st) st = get_int(g, ti, "texCoord", 0, 0, 64, jp, &tc);
    if (!st && scale) st = get_num(g, ti, "scale", 1.0, -1e6, 1e6, jp, scale);
    if (!st && tt) st = texture_transform(g, tt, jp, m, &tc);
    if (!st) st = sampler_flags(g, t, &flags);
    if (st) return st;
    if (tc > 1 && (st = scene_warn(g->s, g->err, "%s: %s: texCoord %lld is read as TEXCOORD_0 (clpt reads "
                                   "TEXCOORD_0 and TEXCOORD_1)", g->path, jp, tc)))
        return st;
    if (tc == 1) flags |= TEX_UV1;
    if ((st = texture_get(g, t, linear, jp, out))) return st;
    if (!flags && !tt) return ST_OK;
    Texture tx = g->s->textures[*out];
    tx.flags |= flags;
    if (tt) texture_set_matrix(&tx, m);
    return scene_add_texture(g->s, NULL, NULL, tx, out, g->err);
}

/* A copy of texture `base` with every texel multiplied by `factor` (glTF's base colour
 * is texture x baseColorFactor; clpt's texture replaces the albedo), its texels linear
 * floats so that the product is exact and filtered as the original would be. */
static Status texture_tinted(Gltf *g, uint base, const double factor[3], uint *out)
{
    Texture t = g->s->textures[base];
    size_t n = (size_t)t.width * t.height;
    uint *texels = malloc(3 * n * sizeof *texels + 1);
    if (!texels) return error_set(g->err, ST_INTERNAL, "out of memory tinting a texture");
    for (size_t i = 0; i < n; i++) {
        float rgb[3];
        if (t.flags & TEX_FLOAT) {
            memcpy(rgb, g->s->texels + t.offset + 3 * i, sizeof rgb);
        } else {
            uint c = g->s->texels[t.offset + i];
            for (int k = 0; k < 3; k++) {
                rgb[k] = (float)((c >> (8 * k)) & 255u) / 255.0f;
                if (t.flags & TEX_SRGB) rgb[k] = k_srgb_to_linear(rgb[k]);
            }
        }
        for (int k = 0; k < 3; k++) {
            float v = rgb[k] * (float)factor[k];
            memcpy(&texels[3 * i + (size_t)k], &v, sizeof v);
        }
    }
    uint offset;
    Status st = scene_add_texels(g->s, texels, 3 * n, &offset, g->err);
    free(texels);
    if (st) return st;
    t.offset = offset;
    t.flags = (t.flags & TEX_SAMPLING) | TEX_FLOAT;
    return scene_add_texture(g->s, NULL, NULL, t, out, g->err);
}

/* alphaMode OPAQUE (the default: alpha ignored), MASK (cut out where alpha, baseColorFactor's
 * A times the base-colour texture's alpha, is below alphaCutoff, default 0.5) or BLEND
 * (a hit kept with probability alpha, kernels/alpha.h). */
static Status material_alpha(Gltf *g, const cJSON *m, const char *jp, double alpha, Material *mt)
{
    char jpa[96];
    snprintf(jpa, sizeof jpa, "%s.alphaMode", jp);
    const cJSON *mode = cJSON_GetObjectItemCaseSensitive(m, "alphaMode");
    mt->alpha = (float)alpha;
    if (!mode) return ST_OK;
    if (!cJSON_IsString(mode)) return bad(g, jpa, "expected \"OPAQUE\", \"MASK\" or \"BLEND\"");
    if (strcmp(mode->valuestring, "MASK") == 0) {
        double cutoff;
        Status st = get_num(g, m, "alphaCutoff", 0.5, 0.0, 1.0, jp, &cutoff);
        if (st) return st;
        mt->alpha_cutoff = (float)cutoff;
        mt->flags |= MAT_ALPHA_MASK;
    } else if (strcmp(mode->valuestring, "BLEND") == 0) {
        mt->flags |= MAT_ALPHA_BLEND;
    } else if (strcmp(mode->valuestring, "OPAQUE") != 0) {
        return bad(g, jpa, "expected \"OPAQUE\", \"MASK\" or \"BLEND\"");
    }
    return ST_OK;
}

/* KHR_materials_volume: thicknessFactor > 0 makes the mesh the boundary of a solid (a
 * path tracer has the real thickness, so neither the factor's value nor thicknessTexture
 * is read), inside which attenuationColor / attenuationDistance absorb (Beer-Lambert,
 * kernels/shade.cl). Thickness 0, the default, keeps the thin wall. */
static Status material_volume(Gltf *g, const cJSON *m, const char *jp, Material *mt)
{
    const cJSON *x = ext_of(m, "KHR_materials_volume");
    if (!x) return ST_OK;
    char jx[128];
    snprintf(jx, sizeof jx, "%s.extensions.KHR_materials_volume", jp);
    static const double white[3] = { 1, 1, 1 };
    double thickness, distance, color[3];
    Status st = get_num(g, x, "thicknessFactor", 0.0, 0.0, 1e30, jx, &thickness);
    if (!st) st = get_num(g, x, "attenuationDistance", INFINITY, 1e-30, INFINITY, jx, &distance);
    if (!st) st = get_nums(g, x, "attenuationColor", 3, white, jx, color);
    if (st) return st;
    if (!(thickness > 0.0)) return ST_OK;
    mt->flags &= ~MAT_THIN;
    mt->absorption = material_absorption(v3((float)color[0], (float)color[1], (float)color[2]), (float)distance);
    return ST_OK;
}

/* KHR_materials_specular: specularFactor (times specularTexture's alpha) and
 * specularColorFactor (times specularColorTexture, sRGB) scale the dielectric F0 and
 * F90 (kernels/principled.h). */
static Status material_specular(Gltf *g, const cJSON *m, const char *jp, Material *mt)
{
    const cJSON *x = ext_of(m, "KHR_materials_specular");
    if (!x) return ST_OK;
    char jx[128];
    snprintf(jx, sizeof jx, "%s.extensions.KHR_materials_specular", jp);
    static const double white[3] = { 1, 1, 1 };
    double factor, color[3];
    Status st = get_num(g, x, "specularFactor", 1.0, 0.0, 1.0, jx, &factor);
    if (!st) st = get_nums(g, x, "specularColorFactor", 3, white, jx, color);
    if (!st) st = texinfo(g, x, "specularTexture", 1, jx, &mt->texture_specular, NULL);
    if (!st) st = texinfo(g, x, "specularColorTexture", 0, jx, &mt->texture_specular_color, NULL);
    if (st) return st;
    mt->specular_factor = (float)factor;
    mt->specular_color = v3((float)color[0], (float)color[1], (float)color[2]);
    return ST_OK;
}

/* KHR_materials_sheen: sheenColorFactor (times sheenColorTexture, sRGB) and
 * sheenRoughnessFactor (times sheenRoughnessTexture's alpha). */
static Status material_sheen(Gltf *g, const cJSON *m, const char *jp, Material *mt)
{
    const cJSON *x = ext_of(m, "KHR_materials_sheen");
    if (!x) return ST_OK;
    char jx[128];
    snprintf(jx, sizeof jx, "%s.extensions.KHR_materials_sheen", jp);
    static const double black[3] = { 0, 0, 0 };
    double color[3], rough;
    Status st = get_nums(g, x, "sheenColorFactor", 3, black, jx, color);
    if (!st) st = get_num(g, x, "sheenRoughnessFactor", 0.0, 0.0, 1.0, jx, &rough);
    if (!st) st = texinfo(g, x, "sheenColorTexture", 0, jx, &mt->texture_sheen_color, NULL);
    if (!st) st = texinfo(g, x, "sheenRoughnessTexture", 1, jx, &mt->texture_sheen_roughness, NULL);
    if (st) return st;
    mt->sheen_color = v3((float)color[0], (float)color[1], (float)color[2]);
    mt->sheen_roughness = (float)rough;
    return ST_OK;
}

static Status material_build(Gltf *g, int i, uint *out)
{
    char jp[64];
    snprintf(jp, sizeof jp, "materials[%d]", i);
    const cJSON *m = item_at(g, "materials", i);
    const cJSON *pbr = cJSON_GetObjectItemCaseSensitive(m, "pbrMetallicRoughness");
    char jpp[96];
    snprintf(jpp, sizeof jpp, "%s.pbrMetallicRoughness", jp);
    static const double ones[4] = { 1, 1, 1, 1 }, zeros[3] = { 0, 0, 0 };
    double base[4], metallic, rough, emit[3], strength = 1.0, nscale = 1.0;
    Status st = get_nums(g, pbr, "baseColorFactor", 4, ones, jpp, base);
    if (!st) st = get_num(g, pbr, "metallicFactor", 1.0, 0.0, 1.0, jpp, &metallic);
    if (!st) st = get_num(g, pbr, "roughnessFactor", 1.0, 0.0, 1.0, jpp, &rough);
    if (!st) st = get_nums(g, m, "emissiveFactor", 3, zeros, jp, emit);
    const cJSON *es = ext_of(m, "KHR_materials_emissive_strength");
    if (!st && es) st = get_num(g, es, "emissiveStrength", 1.0, 0.0, 1e30, jp, &strength);
    if (st) return st;
    Material mt = material_principled(v3((float)base[0], (float)base[1], (float)base[2]), (float)metallic,
                                      (float)rough);
    mt.emission = v3((float)(emit[0] * strength), (float)(emit[1] * strength), (float)(emit[2] * strength));
    if (emit[0] > 0 || emit[1] > 0 || emit[2] > 0) g->has_lights = 1;
    if (cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(m, "doubleSided"))) mt.flags |= MAT_TWO_SIDED;
    if ((st = texinfo(g, pbr, "baseColorTexture", 0, jpp, &mt.texture, NULL))) return st;
    if (mt.texture != NO_INDEX && (base[0] != 1 || base[1] != 1 || base[2] != 1) &&
        (st = texture_tinted(g, mt.texture, base, &mt.texture)))
        return st;
    if ((st = texinfo(g, pbr, "metallicRoughnessTexture", 1, jpp, &mt.texture_rm, NULL))) return st;
    if ((st = texinfo(g, m, "normalTexture", 1, jp, &mt.texture_normal, &nscale))) return st;
    mt.normal_scale = (float)nscale;
    /* the emissive texture is sRGB-encoded, like the base colour (glTF 2.0, 3.9.5) */
    if ((st = texinfo(g, m, "emissiveTexture", 0, jp, &mt.texture_emission, NULL))) return st;
    if ((st = material_alpha(g, m, jp, base[3], &mt))) return st;
    double v;
    const cJSON *x;
    if ((x = ext_of(m, "KHR_materials_ior"))) {
        if ((st = get_num(g, x, "ior", 1.5, 1.0, 10.0, jp, &v))) return st;
        mt.ior = (float)v;
    }
    if ((x = ext_of(m, "KHR_materials_transmission"))) {
        if ((st = get_num(g, x, "transmissionFactor", 0.0, 0.0, 1.0, jp, &v))) return st;
        mt.transmission = (float)v;
        mt.flags |= MAT_THIN;   /* without KHR_materials_volume a glTF surface is a thin wall */
    }
    if ((x = ext_of(m, "KHR_materials_clearcoat"))) {
        if ((st = get_num(g, x, "clearcoatFactor", 0.0, 0.0, 1.0, jp, &v))) return st;
        mt.clearcoat = (float)v;
        if ((st = get_num(g, x, "clearcoatRoughnessFactor", 0.0, 0.0, 1.0, jp, &v))) return st;
        mt.clearcoat_roughness = (float)v;
    }
    if ((st = material_volume(g, m, jp, &mt)) || (st = material_specular(g, m, jp, &mt)) ||
        (st = material_sheen(g, m, jp, &mt)))
        return st;
    const cJSON *name = cJSON_GetObjectItemCaseSensitive(m, "name");
    return scene_add_material(g->s, cJSON_IsString(name) ? name->valuestring : "", mt, out, g->err);
}

static Status material_get(Gltf *g, int i, uint *out)
{
    if (g->o->material != NO_INDEX) {
        *out = g->o->material;
        return ST_OK;
    }
    uint *slot = i < 0 ? &g->default_mat : &g->mats[i];
    if (*slot == NO_INDEX) {
        /* glTF's default material: white, metallic 1, roughness 1 */
        Status st = i < 0 ? scene_add_material(g->s, "", material_principled(v3s(1.0f), 1.0f, 1.0f), slot, g->err)
                          : material_build(g, i, slot);
        if (st) return st;
    }
    *out = *slot;
    return ST_OK;
}

/* ------------------------------------------------------------------ primitives */

static Status corner_indices(Gltf *g, const cJSON *prim, const char *jp, size_t n_vertices, uint32_t **idx,
                             size_t *n)
{
    int ai;
    Status st = get_index(g, prim, "indices", 0, "accessors", jp, &ai);
    if (st) return st;
    *idx = malloc((ai < 0 ? n_vertices : 1) * sizeof **idx);
    if (ai < 0) {
        if (!*idx) return error_set(g->err, ST_INTERNAL, "out of memory");
        for (size_t i = 0; i < n_vertices; i++) (*idx)[i] = (uint32_t)i;
        *n = n_vertices;
        return ST_OK;
    }
    free(*idx);
    *idx = NULL;
    char use[120];
    snprintf(use, sizeof use, "%s.indices", jp);
    double *d;
    if ((st = acc_read(g, ai, 1, use, &d, n))) return st;
    *idx = malloc(*n * sizeof **idx);
    if (!*idx) {
        free(d);
        return error_set(g->err, ST_INTERNAL, "out of memory");
    }
    for (size_t i = 0; i < *n; i++) {
        if (!(d[i] >= 0 && d[i] < (double)n_vertices)) {
            st = error_set(g->err, ST_INPUT, "%s: %s: index %zu is %.0f, past the %zu vertices", g->path, use, i, d[i],
                           n_vertices);
            break;
        }
        (*idx)[i] = (uint32_t)d[i];
    }
    free(d);
    if (st) {
        free(*idx);
        *idx = NULL;
    }
    return st;
}

/* attributes.name as `width`-wide elements (or `width2`-wide, 0: only width; *got says
 * which), as many as POSITION's n_vertices; *out NULL when the primitive lacks it. */
static Status attr_read(Gltf *g, const cJSON *attrs, const char *name, int width, int width2, const char *jp,
                        size_t n_vertices, double **out, int *got)
{
    *out = NULL;
    char use[140];
    snprintf(use, sizeof use, "%s.attributes.%s", jp, name);
    int ai;
    Status st = get_index(g, attrs, name, 0, "accessors", use, &ai);
    if (st || ai < 0) return st;
    if (strcmp(name, "COLOR_0") == 0) {
        /* glTF 2.0, 3.7.2.1: float, or normalized unsigned byte or short */
        const cJSON *acc = item_at(g, "accessors", ai);
        const cJSON *ct = cJSON_GetObjectItemCaseSensitive(acc, "componentType");
        double c = cJSON_IsNumber(ct) ? ct->valuedouble : 0;
        int norm = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(acc, "normalized"));
        if (!(c == 5126 || ((c == 5121 || c == 5123) && norm)))
            return error_set(g->err, ST_INPUT, "%s: %s: accessor %d: componentType must be 5126 (float), or 5121 "
                             "or 5123 (unsigned byte or short) with normalized true", g->path, use, ai);
    }
    size_t n;
    if ((st = acc_read_either(g, ai, width, width2, use, out, &n, got))) return st;
    if (n_vertices && n != n_vertices) {
        free(*out);
        *out = NULL;
        return error_set(g->err, ST_INPUT, "%s: %s: accessor %d has %zu elements, POSITION has %zu", g->path, use, ai,
                         n, n_vertices);
    }
    return ST_OK;
}

/* A primitive's vertex attributes, as doubles per vertex (NULL when absent). */
typedef struct {
    double *pos, *nrm, *uv;
    double *tan, *uv1, *col;    /* TANGENT (4 wide), TEXCOORD_1, COLOR_0 (col_width wide) */
    int col_width;
} Attrs;

static void attrs_free(Attrs *a)
{
    free(a->pos);
    free(a->nrm);
    free(a->uv);
    free(a->tan);
    free(a->uv1);
    free(a->col);
}

/* A glTF uv as clpt's: glTF's v runs down the image, clpt's (as OBJ's) up. */
static void uv_flip(const double *uv, float *out)
{
    out[0] = (float)uv[0];
    out[1] = (float)(1.0 - uv[1]);
}

/* One triangle of vertices a, b, c. */
static Status emit(MeshSink *k, const Attrs *at, uint32_t a, uint32_t b, uint32_t c, uint mat)
{
    const uint32_t v[3] = { a, b, c };
    vec3 p[3], n[3];
    float t[6];
    TriExtra e;
    memset(&e, 0, sizeof e);
    e.flags = (at->tan ? EXTRA_TANGENT : 0u) | (at->uv1 ? EXTRA_UV1 : 0u) | (at->col ? EXTRA_COLOR : 0u);
    int normals_ok = at->nrm != NULL, uv_ok = at->uv != NULL;
    for (int i = 0; i < 3; i++) {
        size_t vi = v[i];
        const double *q = at->pos + 3 * vi;
        p[i] = v3((float)q[0], (float)q[1], (float)q[2]);
        if (at->nrm) {
            const double *m = at->nrm + 3 * vi;
            double l = sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]);
            if (!(l > 0) || !isfinite(l)) normals_ok = 0;
            else n[i] = v3((float)(m[0] / l), (float)(m[1] / l), (float)(m[2] / l));
        }
        if (at->uv) {
            uv_flip(at->uv + 2 * vi, t + 2 * i);
            if (!isfinite(t[2 * i]) || !isfinite(t[2 * i + 1])) uv_ok = 0;
        }
        /* the sink checks these for finiteness and transforms the tangents */
        for (int j = 0; at->tan && j < 4; j++) e.tangent[i][j] = (float)at->tan[4 * vi + (size_t)j];
        if (at->uv1) uv_flip(at->uv1 + 2 * vi, e.uv[i]);
        for (int j = 0; at->col && j < 4; j++)
            e.color[i][j] = j < at->col_width ? (float)at->col[(size_t)at->col_width * vi + (size_t)j] : 1.0f;
    }
    return mesh_sink_triangle_extra(k, p, normals_ok ? n : NULL, uv_ok ? t : NULL, e.flags ? &e : NULL, mat);
}

/* Counts the `n` triangles a primitive is about to make (reached through node `node`)
 * against the file's bound, before any is made. */
static Status triangles_count(Gltf *g, size_t n, const char *node, const char *jp)
{
    if (n <= g->max_triangles - g->triangles) {
        g->triangles += n;
        return ST_OK;
    }
    return error_set(g->err, ST_INPUT, "%s: %s (in %s): its %zu triangles bring the file's to %llu, more than the %zu "
                     "a file of its size may make (2^20 and one per byte of the file and its buffers, at most 2^26; "
                     "every node's instance counts)", g->path, jp, node, n,
                     (unsigned long long)g->triangles + n, g->max_triangles);
}

static Status primitive_load(Gltf *g, MeshSink *k, const cJSON *prim, const char *jp, const char *node)
{
    long long mode;
    Status st = get_int(g, prim, "mode", 4, 0, 6, jp, &mode);
    if (st) return st;
    if (mode < 4)
        return scene_warn(g->s, g->err, "%s: %s: mode %lld (points or lines) is not drawn", g->path, jp, mode);
    const cJSON *attrs = cJSON_GetObjectItemCaseSensitive(prim, "attributes");
    if (!cJSON_IsObject(attrs)) return bad(g, jp, "attributes: expected an object");
    if (!cJSON_GetObjectItemCaseSensitive(attrs, "POSITION")) return bad(g, jp, "attributes.POSITION: missing");
    Attrs at;
    memset(&at, 0, sizeof at);
    uint32_t *idx = NULL;
    size_t nv = 0, ni = 0;
    char use[140];
    snprintf(use, sizeof use, "%s.attributes.POSITION", jp);
    int pa, w;
    if ((st = get_index(g, attrs, "POSITION", 1, "accessors", use, &pa))) return st;
    if ((st = acc_read(g, pa, 3, use, &at.pos, &nv))) return st;
    uint mat;
    int mi;
    if (!(st = attr_read(g, attrs, "NORMAL", 3, 0, jp, nv, &at.nrm, &w)) &&
        !(st = attr_read(g, attrs, "TEXCOORD_0", 2, 0, jp, nv, &at.uv, &w)) &&
        !(st = attr_read(g, attrs, "TANGENT", 4, 0, jp, nv, &at.tan, &w)) &&
        !(st = attr_read(g, attrs, "TEXCOORD_1", 2, 0, jp, nv, &at.uv1, &w)) &&
        !(st = attr_read(g, attrs, "COLOR_0", 3, 4, jp, nv, &at.col, &at.col_width)) &&
        !(st = corner_indices(g, prim, jp, nv, &idx, &ni)) &&
        !(st = get_index(g, prim, "material", 0, "materials", jp, &mi)))
        st = material_get(g, mi, &mat);
    if (!st && ni >= 3) st = triangles_count(g, mode == 4 ? ni / 3 : ni - 2, node, jp);
    if (!st && mode == 4) {
        for (size_t i = 0; i + 2 < ni && !st; i += 3) st = emit(k, &at, idx[i], idx[i + 1], idx[i + 2], mat);
    } else if (!st && mode == 5) {
        /* every other triangle of a strip swaps its first two corners to keep the winding */
        for (size_t i = 0; i + 2 < ni && !st; i++)
            st = i % 2 ? emit(k, &at, idx[i + 1], idx[i], idx[i + 2], mat)
                       : emit(k, &at, idx[i], idx[i + 1], idx[i + 2], mat);
    } else if (!st) {
        for (size_t i = 0; i + 2 < ni && !st; i++) st = emit(k, &at, idx[i + 1], idx[i + 2], idx[0], mat);
    }
    attrs_free(&at);
    free(idx);
    return st;
}

static Status mesh_instance(Gltf *g, int mesh, const Transform *xf, const char *node)
{
    char jp[64];
    snprintf(jp, sizeof jp, "meshes[%d]", mesh);
    const cJSON *prims = cJSON_GetObjectItemCaseSensitive(item_at(g, "meshes", mesh), "primitives");
    if (!cJSON_IsArray(prims)) return bad(g, jp, "primitives: expected an array");
    MeshSink k;
    Status st = mesh_sink_open(&k, g->s, xf, g->path, g->err);
    int i = 0;
    for (const cJSON *p = first_of(prims); !st && p; p = p->next, i++) {
        char jpp[96];
        snprintf(jpp, sizeof jpp, "%s.primitives[%d]", jp, i);
        st = primitive_load(g, &k, p, jpp, node);
    }
    return st;
}

/* ------------------------------------------------------------------ nodes */

static Status node_local(Gltf *g, const cJSON *node, const char *jp, Transform *out)
{
    double m[16];
    static const double ident[16] = { 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1 };
    static const double t0[3] = { 0, 0, 0 }, r0[4] = { 0, 0, 0, 1 }, s0[3] = { 1, 1, 1 };
    Status st;
    if (cJSON_GetObjectItemCaseSensitive(node, "matrix")) {
        if ((st = get_nums(g, node, "matrix", 16, ident, jp, m))) return st;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 4; c++) out->m[r][c] = m[4 * c + r];   /* column-major */
        return ST_OK;
    }
    double t[3], q[4], sc[3];
    if ((st = get_nums(g, node, "translation", 3, t0, jp, t)) || (st = get_nums(g, node, "rotation", 4, r0, jp, q)) ||
        (st = get_nums(g, node, "scale", 3, s0, jp, sc)))
        return st;
    double l = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (!(l > 0)) return bad(g, jp, "rotation: a zero quaternion");
    double x = q[0] / l, y = q[1] / l, z = q[2] / l, w = q[3] / l;
    const double r[3][3] = {
        { 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w) },
        { 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w) },
        { 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y) },
    };
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) out->m[i][j] = r[i][j] * sc[j];
        out->m[i][3] = t[i];
    }
    return ST_OK;
}

static vec3 xf_dir(const Transform *t, double x, double y, double z)
{
    double v[3];
    for (int i = 0; i < 3; i++) v[i] = t->m[i][0] * x + t->m[i][1] * y + t->m[i][2] * z;
    double l = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    if (!(l > 0)) l = 1;
    return v3((float)(v[0] / l), (float)(v[1] / l), (float)(v[2] / l));
}

static int camera_wanted(const Gltf *g, int cam, const cJSON *node)
{
    const char *want = g->view->camera;
    if (!want) return !g->view->has_camera;
    char *end;
    long v = strtol(want, &end, 10);
    if (*want && !*end) return v == cam;
    const cJSON *cn = cJSON_GetObjectItemCaseSensitive(item_at(g, "cameras", cam), "name");
    const cJSON *nn = cJSON_GetObjectItemCaseSensitive(node, "name");
    return (cJSON_IsString(cn) && strcmp(cn->valuestring, want) == 0) ||
           (cJSON_IsString(nn) && strcmp(nn->valuestring, want) == 0);
}

static Status camera_set(Gltf *g, int cam, const Transform *xf)
{
    char jp[64];
    snprintf(jp, sizeof jp, "cameras[%d]", cam);
    const cJSON *c = item_at(g, "cameras", cam);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(c, "type");
    SceneCamera *sc = &g->s->camera;
    int ortho = cJSON_IsString(type) && strcmp(type->valuestring, "orthographic") == 0;
    double aspect = 0, v;
    Status st;
    if (ortho) {
        const cJSON *o = cJSON_GetObjectItemCaseSensitive(c, "orthographic");
        if ((st = get_num(g, o, "ymag", 1.0, 1e-30, 1e30, jp, &v))) return st;
        sc->type = CAMERA_ORTHOGRAPHIC;
        sc->ortho_height = (float)(2.0 * v);
        double xmag;
        if ((st = get_num(g, o, "xmag", 0.0, 0.0, 1e30, jp, &xmag))) return st;
        aspect = xmag > 0 ? xmag / v : 0;
    } else {
        const cJSON *p = cJSON_GetObjectItemCaseSensitive(c, "perspective");
        if (!cJSON_IsObject(p)) return bad(g, jp, "perspective: expected an object");
        if ((st = get_num(g, p, "yfov", -1.0, 1e-6, 3.14, jp, &v))) return st;
        if (v < 0) return bad(g, jp, "perspective.yfov: missing (required)");
        if ((st = get_num(g, p, "aspectRatio", 0.0, 1e-3, 1e3, jp, &aspect))) return st;
        sc->type = CAMERA_PERSPECTIVE;
        sc->vfov = (float)(v * 180.0 / M_PI);
    }
    sc->from = transform_point(xf, v3(0.0f, 0.0f, 0.0f));
    vec3 fwd = xf_dir(xf, 0, 0, -1);
    sc->at = v3(sc->from.x + fwd.x, sc->from.y + fwd.y, sc->from.z + fwd.z);
    sc->up = xf_dir(xf, 0, 1, 0);
    sc->aperture = 0.0f;
    sc->focus_dist = 0.0f;
    if (!isfinite(sc->from.x) || !isfinite(sc->from.y) || !isfinite(sc->from.z) || !isfinite(sc->at.x) ||
        !isfinite(sc->at.y) || !isfinite(sc->at.z))
        return bad(g, jp, "its node puts the camera beyond the float range");
    if (aspect > 0) {
        double h = floor(g->s->image.width / aspect + 0.5);
        g->s->image.height = (uint)fmax(1.0, fmin(h, (double)CLPT_MAX_IMAGE_SIDE));
    }
    g->view->has_camera = 1;
    return ST_OK;
}

static Status light_add(Gltf *g, int li, const Transform *xf, const char *jp)
{
    const cJSON *l = item_at(g, "lights", li);
    if (li < 0 || !l) return bad(g, jp, "KHR_lights_punctual.light names no light of the file's extensions");
    char jl[80];
    snprintf(jl, sizeof jl, "extensions.KHR_lights_punctual.lights[%d]", li);
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(l, "type");
    const char *t = cJSON_IsString(type) ? type->valuestring : "";
    static const double white[3] = { 1, 1, 1 };
    double color[3], intensity;
    Status st = get_nums(g, l, "color", 3, white, jl, color);
    if (!st) st = get_num(g, l, "intensity", 1.0, 0.0, 1e30, jl, &intensity);
    if (st) return st;
    uint lt = strcmp(t, "point") == 0 ? LIGHT_POINT : strcmp(t, "spot") == 0 ? LIGHT_SPOT
            : strcmp(t, "directional") == 0 ? LIGHT_DIRECTIONAL : NO_INDEX;
    if (lt == NO_INDEX) return bad(g, jl, "type: expected point, spot or directional");
    Light L = light_default(lt);
    Transform w = transform_compose(&g->o->xf, xf);
    L.position = transform_point(&w, v3(0.0f, 0.0f, 0.0f));
    L.direction = xf_dir(&w, 0, 0, -1);
    if (!isfinite(L.position.x) || !isfinite(L.position.y) || !isfinite(L.position.z))
        return bad(g, jp, "its transform puts the light beyond the float range");
    double k = intensity / LUMENS_PER_WATT;
    L.intensity = v3((float)(color[0] * k), (float)(color[1] * k), (float)(color[2] * k));
    if (lt == LIGHT_SPOT) {
        const cJSON *sp = cJSON_GetObjectItemCaseSensitive(l, "spot");
        double inner, outer;
        if ((st = get_num(g, sp, "innerConeAngle", 0.0, 0.0, M_PI / 2, jl, &inner)) ||
            (st = get_num(g, sp, "outerConeAngle", M_PI / 4, 0.0, M_PI / 2, jl, &outer)))
            return st;
        L.cos_outer = (float)cos(outer);
        L.cos_inner = (float)cos(fmin(inner, outer));
        L.spot_falloff = SPOT_GLTF;
    }
    g->has_lights = 1;
    return scene_add_light(g->s, L, g->err);
}

static Status node_visit(Gltf *g, int n, const Transform *parent, int depth)
{
    char jp[64];
    snprintf(jp, sizeof jp, "nodes[%d]", n);
    if (g->visited[n]) return bad(g, jp, "reached twice in the node tree (a node has one parent, no cycles)");
    if (depth > CLPT_MAX_NESTING) return bad(g, jp, "the node tree is nested too deep");
    g->visited[n] = 1;
    const cJSON *node = item_at(g, "nodes", n);
    Transform local, xf;
    Status st = node_local(g, node, jp, &local);
    if (st) return st;
    xf = transform_compose(parent, &local);
    int mesh, cam;
    if ((st = get_index(g, node, "mesh", 0, "meshes", jp, &mesh))) return st;
    if ((st = get_index(g, node, "camera", 0, "cameras", jp, &cam))) return st;
    if (mesh >= 0) {
        Transform w = transform_compose(&g->o->xf, &xf);
        if ((st = mesh_instance(g, mesh, &w, jp))) return st;
    }
    if (cam >= 0 && g->view && camera_wanted(g, cam, node)) {
        Transform w = transform_compose(&g->o->xf, &xf);
        if ((st = camera_set(g, cam, &w))) return st;
    }
    const cJSON *lp = ext_of(node, "KHR_lights_punctual");
    if (lp) {
        long long li;
        if ((st = get_int(g, lp, "light", -1, 0, INT32_MAX, jp, &li)) || (st = light_add(g, (int)li, &xf, jp)))
            return st;
    }
    const cJSON *kids = cJSON_GetObjectItemCaseSensitive(node, "children");
    int i = 0;
    for (const cJSON *c = first_of(kids); c; c = c->next, i++) {
        if (!cJSON_IsNumber(c) || c->valuedouble < 0 || c->valuedouble >= g->n_nodes ||
            c->valuedouble != floor(c->valuedouble)) {
            char jc[96];
            snprintf(jc, sizeof jc, "%s.children[%d]", jp, i);
            return bad(g, jc, "not the index of a node");
        }
        if ((st = node_visit(g, (int)c->valuedouble, &xf, depth + 1))) return st;
    }
    return ST_OK;
}

static Status scene_walk(Gltf *g)
{
    const Transform id = transform_identity();
    int n_scenes = g->t[T_SCENES].n;
    long long sc;
    Status st = get_int(g, g->root, "scene", 0, 0, n_scenes > 0 ? n_scenes - 1 : 0, "(top level)", &sc);
    if (st) return st;
    if (n_scenes > 0) {
        char jp[64];
        snprintf(jp, sizeof jp, "scenes[%lld].nodes", sc);
        const cJSON *roots = cJSON_GetObjectItemCaseSensitive(g->t[T_SCENES].item[sc], "nodes");
        for (const cJSON *r = first_of(roots); r; r = r->next) {
            if (!cJSON_IsNumber(r) || r->valuedouble < 0 || r->valuedouble >= g->n_nodes ||
                r->valuedouble != floor(r->valuedouble))
                return bad(g, jp, "an entry is not the index of a node");
            if ((st = node_visit(g, (int)r->valuedouble, &id, 0))) return st;
        }
        return ST_OK;
    }
    /* no scenes: every node that is no other node's child is a root */
    unsigned char *child = calloc((size_t)g->n_nodes + 1, 1);
    if (!child) return error_set(g->err, ST_INTERNAL, "out of memory");
    for (int n = 0; n < g->n_nodes; n++) {
        const cJSON *kids = cJSON_GetObjectItemCaseSensitive(item_at(g, "nodes", n), "children");
        for (const cJSON *c = first_of(kids); c; c = c->next) {
            if (cJSON_IsNumber(c) && c->valuedouble >= 0 && c->valuedouble < g->n_nodes) child[(int)c->valuedouble] = 1;
        }
    }
    for (int n = 0; n < g->n_nodes && !st; n++)
        if (!child[n]) st = node_visit(g, n, &id, 0);
    free(child);
    return st;
}

/* ------------------------------------------------------------------ the file */

static const char *const supported_ext[] = {
    "KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_ior",
    "KHR_materials_transmission", "KHR_materials_clearcoat", "KHR_texture_transform",
    "KHR_materials_volume", "KHR_materials_specular", "KHR_materials_sheen",
};

static int ext_supported(const char *name)
{
    for (size_t i = 0; i < sizeof supported_ext / sizeof *supported_ext; i++)
        if (strcmp(name, supported_ext[i]) == 0) return 1;
    return 0;
}

static Status extensions_check(Gltf *g)
{
    const cJSON *req = cJSON_GetObjectItemCaseSensitive(g->root, "extensionsRequired");
    int i = 0;
    for (const cJSON *e = first_of(req); e; e = e->next, i++) {
        if (cJSON_IsString(e) && !ext_supported(e->valuestring))
            return error_set(g->err, ST_INPUT, "%s: extensionsRequired[%d]: the file requires the extension '%s', "
                             "which clpt does not support", g->path, i, e->valuestring);
    }
    const cJSON *used = cJSON_GetObjectItemCaseSensitive(g->root, "extensionsUsed");
    for (const cJSON *e = first_of(used); e; e = e->next) {
        Status st;
        if (cJSON_IsString(e) && !ext_supported(e->valuestring) &&
            (st = scene_warn(g->s, g->err, "%s: the extension '%s' (extensionsUsed) is ignored", g->path,
                             e->valuestring)))
            return st;
    }
    return ST_OK;
}

/* The GLB container: header (magic, version 2, total length), a JSON chunk, and an
 * optional BIN chunk; every length checked against the file. */
static Status glb_split(Gltf *g, const unsigned char *d, size_t len, const char **json, size_t *json_len)
{
    if (len < 12 || bytes_get_le32(d) != GLB_MAGIC)
        return error_set(g->err, ST_INPUT, "%s: not a binary glTF file (it does not start with the magic 'glTF')",
                         g->path);
    if (bytes_get_le32(d + 4) != 2)
        return error_set(g->err, ST_INPUT, "%s: GLB version %u; clpt reads version 2", g->path, bytes_get_le32(d + 4));
    if (bytes_get_le32(d + 8) != len)
        return error_set(g->err, ST_INPUT, "%s: the GLB header says the file has %u bytes, but it has %zu", g->path,
                         bytes_get_le32(d + 8), len);
    size_t at = 12;
    for (int chunk = 0; at < len; chunk++) {
        if (len - at < 8)
            return error_set(g->err, ST_INPUT, "%s: GLB chunk %d at byte %zu: its 8-byte header is cut off", g->path,
                             chunk, at);
        uint32_t clen = bytes_get_le32(d + at), type = bytes_get_le32(d + at + 4);
        if (clen > len - at - 8)
            return error_set(g->err, ST_INPUT, "%s: GLB chunk %d at byte %zu declares %u bytes, more than the %zu "
                             "left in the file", g->path, chunk, at, clen, len - at - 8);
        if (chunk == 0) {
            if (type != GLB_JSON)
                return error_set(g->err, ST_INPUT, "%s: the first GLB chunk is not JSON", g->path);
            *json = (const char *)d + at + 8;
            *json_len = clen;
        } else if (chunk == 1 && type == GLB_BIN) {
            g->bin = d + at + 8;
            g->bin_len = clen;
        }
        at += 8 + (size_t)clen;
    }
    if (!*json) return error_set(g->err, ST_INPUT, "%s: the GLB file has no JSON chunk", g->path);
    return ST_OK;
}

static Status gltf_read(Gltf *g, const char *data, size_t len)
{
    const char *json = data;
    size_t json_len = len;
    Status st;
    if (len >= 4 && memcmp(data, "glTF", 4) == 0) {
        json = NULL;
        if ((st = glb_split(g, (const unsigned char *)data, len, &json, &json_len))) return st;
    } else if (strlen(g->path) >= 4 && strcasecmp(g->path + strlen(g->path) - 4, ".glb") == 0) {
        return error_set(g->err, ST_INPUT, "%s: not a binary glTF file (it does not start with the magic 'glTF')",
                         g->path);
    }
    g->root = cJSON_ParseWithLength(json, json_len);
    if (!g->root || !cJSON_IsObject(g->root)) {
        const char *at = cJSON_GetErrorPtr();
        size_t off = at && at >= json && at <= json + json_len ? (size_t)(at - json) : 0;
        return error_set(g->err, ST_INPUT, "%s: not valid glTF JSON (the parser stopped at byte %zu of the JSON)",
                         g->path, off);
    }
    const cJSON *asset = cJSON_GetObjectItemCaseSensitive(g->root, "asset");
    const cJSON *ver = cJSON_GetObjectItemCaseSensitive(asset, "version");
    if (!cJSON_IsString(ver) || strncmp(ver->valuestring, "2.", 2) != 0)
        return bad(g, "asset.version", "missing or not 2.x (clpt reads glTF 2.0)");
    if ((st = extensions_check(g)) || (st = tables_build(g)) || (st = buffers_load(g))) return st;
    uint64_t bytes = len;
    for (int i = 0; i < g->n_bufs; i++) bytes += g->bufs[i].len;
    g->max_triangles = (size_t)fmin((double)GLTF_MAX_TRIANGLES, (double)((1u << 20) + GLTF_TRIANGLES_PER_BYTE * bytes));
    g->n_mats = g->t[T_MATERIALS].n;
    g->n_images = g->t[T_IMAGES].n;
    g->n_nodes = g->t[T_NODES].n;
    g->mats = malloc(((size_t)g->n_mats + 1) * sizeof *g->mats);
    g->tex = malloc(((size_t)g->n_images * 2 + 1) * sizeof *g->tex);
    g->visited = calloc((size_t)g->n_nodes + 1, 1);
    if (!g->mats || !g->tex || !g->visited) return error_set(g->err, ST_INTERNAL, "out of memory");
    for (int i = 0; i < g->n_mats; i++) g->mats[i] = NO_INDEX;
    for (int i = 0; i < 2 * g->n_images; i++) g->tex[i] = NO_INDEX;
    if ((st = scene_walk(g))) return st;
    if (g->view && g->view->camera && !g->view->has_camera)
        return error_set(g->err, ST_INPUT, "%s: no camera '%s' (give a camera's index or its or its node's name)",
                         g->path, g->view->camera);
    return ST_OK;
}

Status gltf_parse(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o, GltfView *view,
                  Error *err)
{
    Gltf g;
    memset(&g, 0, sizeof g);
    g.path = path;
    g.s = s;
    g.err = err;
    g.o = o;
    g.view = view;
    g.default_mat = NO_INDEX;
    g.reading_buffer = -1;
    if (view) view->has_camera = 0;
    Status st = gltf_read(&g, data, len);
    if (view) view->has_lights = g.has_lights;
    cJSON_Delete(g.root);
    for (int i = 0; i < g.n_bufs; i++) free(g.bufs[i].owned);
    free(g.bufs);
    free(g.mats);
    free(g.tex);
    free(g.visited);
    strmap_free(&g.buffer_files);
    strmap_free(&g.image_sources[0]);
    strmap_free(&g.image_sources[1]);
    for (int i = 0; i < T_N; i++) free(g.t[i].item);
    return st;
}
