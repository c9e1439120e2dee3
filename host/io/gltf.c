/* gltf.c — glTF 2.0 and GLB scenes (gltf.h): the container; the parts are in gltf_reader.h. */
#include "io/gltf.h"
#include "io/gltf_reader.h"

#include "base/bytes.h"
#include "base/limit.h"
#include "base/strmap.h"
#include "io/lexer.h"
#include "io/path.h"
#include "io/reader.h"
#include "io/texture.h"
#include "util/kmath.h"

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include <cjson/cJSON.h>


static const char *const table_names[T_N] = { "buffers", "bufferViews", "accessors", "meshes", "materials",
                                              "textures", "images", "samplers", "cameras", "nodes", "scenes",
                                              "lights" };

/* ------------------------------------------------------------------ JSON helpers */

Status gltf_bad(Gltf *g, const char *jpath, const char *what)
{
    return error_set(g->err, ST_INPUT, "%s: %s: %s", g->path, jpath, what);
}

static int count_of(const cJSON *a) { return cJSON_IsArray(a) ? cJSON_GetArraySize(a) : 0; }

/* The first element of an array (walk on with ->next), or NULL. */
const cJSON *gltf_first_of(const cJSON *a) { return cJSON_IsArray(a) ? a->child : NULL; }

static const Table *table_of(const Gltf *g, const char *array)
{
    for (int i = 0; i < T_N; i++)
        if (strcmp(table_names[i], array) == 0) return &g->t[i];
    return &g->t[T_N - 1];   /* not reached: every caller names a table */
}

/* The integer at obj.key in [lo, hi], or def when absent (def < lo: required). */
Status gltf_get_int(Gltf *g, const cJSON *obj, const char *key, long long def, long long lo, long long hi,
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
Status gltf_get_index(Gltf *g, const cJSON *obj, const char *key, int required, const char *array,
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
    Status st = gltf_get_int(g, obj, key, -1, 0, n - 1, jpath, &v);
    if (st) return st;
    *out = (int)v;
    return ST_OK;
}

Status gltf_get_num(Gltf *g, const cJSON *obj, const char *key, double def, double lo, double hi,
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
Status gltf_get_nums(Gltf *g, const cJSON *obj, const char *key, int n, const double *def, const char *jpath,
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

const cJSON *gltf_ext_of(const cJSON *obj, const char *name)
{
    return cJSON_GetObjectItemCaseSensitive(cJSON_GetObjectItemCaseSensitive(obj, "extensions"), name);
}

const cJSON *gltf_item_at(const Gltf *g, const char *array, int i)
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
    for (const cJSON *c = gltf_first_of(a); c; c = c->next) t->item[i++] = c;
    return ST_OK;
}

static Status tables_build(Gltf *g)
{
    for (int i = 0; i < T_N; i++) {
        const cJSON *a = i == T_LIGHTS ? cJSON_GetObjectItemCaseSensitive(
                                             gltf_ext_of(g->root, "KHR_lights_punctual"), "lights")
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
Status gltf_uri_file(Gltf *g, const char *uri, const char *jpath, char **file)
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
        return gltf_bad(g, jpath, "an absolute path (clpt reads data: URIs and file names relative to the glTF file)");
    }
    path_resolve(g->path, name, len, PATH_BESIDE, file);
    free(name);
    return *file ? ST_OK : error_set(g->err, ST_INTERNAL, "out of memory");
}

/* The bytes a `uri` names: a data: URI (base64) or a relative file beside the glTF. */
Status gltf_uri_read(Gltf *g, const char *uri, const char *jpath, Buf *out)
{
    if (strncmp(uri, "data:", 5) == 0) {
        const char *b64 = strstr(uri, ";base64,");
        if (!b64) return gltf_bad(g, jpath, "a data: URI that is not base64");
        return b64_decode(g, jpath, b64 + 8, out);
    }
    char *file;
    Status st = gltf_uri_file(g, uri, jpath, &file);
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
        Status st = gltf_get_int(g, b, "byteLength", -1, 1, (long long)CLPT_MAX_FILE_BYTES, jp, &length);
        if (st) return st;
        const cJSON *uri = cJSON_GetObjectItemCaseSensitive(b, "uri");
        Buf *f = &g->bufs[i];
        if (uri) {
            if (!cJSON_IsString(uri)) return gltf_bad(g, jp, "uri: expected a string");
            char jpu[80];
            snprintf(jpu, sizeof jpu, "%s.uri", jp);
            g->reading_buffer = i;
            st = gltf_uri_read(g, uri->valuestring, jpu, f);
            g->reading_buffer = -1;
            if (st) return st;
        } else if (i == 0 && g->bin) {
            f->p = g->bin;
            f->len = f->whole = g->bin_len;
        } else {
            return gltf_bad(g, jp, "no uri, and it is not the GLB's BIN chunk");
        }
        if ((unsigned long long)length > f->len)
            return error_set(g->err, ST_INPUT, "%s: %s: byteLength is %lld but the data has %zu bytes", g->path, jp,
                             length, f->len);
        f->len = (size_t)length;
    }
    return ST_OK;
}

/* The bytes of bufferViews[v] and its byteStride (0 when not given). */
Status gltf_view_bytes(Gltf *g, int v, Buf *out, size_t *stride)
{
    char jp[64];
    snprintf(jp, sizeof jp, "bufferViews[%d]", v);
    const cJSON *bv = gltf_item_at(g, "bufferViews", v);
    int b;
    long long off, len, st_;
    Status st = gltf_get_index(g, bv, "buffer", 1, "buffers", jp, &b);
    if (!st) st = gltf_get_int(g, bv, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jp, &off);
    if (!st) st = gltf_get_int(g, bv, "byteLength", -1, 1, (long long)CLPT_MAX_FILE_BYTES, jp, &len);
    if (!st) st = gltf_get_int(g, bv, "byteStride", 0, 0, 252, jp, &st_);
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
    if (!cJSON_IsObject(ix) || !cJSON_IsObject(vx)) return gltf_bad(g, jp, "needs indices and values objects");
    int iview, vview;
    Status st = gltf_get_int(g, sp, "count", -1, 1, count, jp, &n);
    char jpi[300], jpv[300];
    snprintf(jpi, sizeof jpi, "%s.indices", jp);
    snprintf(jpv, sizeof jpv, "%s.values", jp);
    if (!st) st = gltf_get_index(g, ix, "bufferView", 1, "bufferViews", jpi, &iview);
    if (!st) st = gltf_get_int(g, ix, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jpi, &ioff);
    if (!st) st = gltf_get_int(g, ix, "componentType", -1, 5121, 5125, jpi, &itype);
    if (!st) st = gltf_get_index(g, vx, "bufferView", 1, "bufferViews", jpv, &vview);
    if (!st) st = gltf_get_int(g, vx, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jpv, &voff);
    if (st) return st;
    if (itype != 5121 && itype != 5123 && itype != 5125)
        return gltf_bad(g, jpi, "componentType must be 5121, 5123 or 5125");
    Buf ib, vb;
    size_t stride;
    if ((st = gltf_view_bytes(g, iview, &ib, &stride)) || (st = gltf_view_bytes(g, vview, &vb, &stride))) return st;
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

/* accessors[a] as `width`-wide elements of doubles (*out, *count elements), read for
 * the JSON path `use`. */
Status gltf_acc_read(Gltf *g, int a, int width, const char *use, double **out, size_t *count)
{
    int got;
    return gltf_acc_read_either(g, a, width, 0, use, out, count, &got);
}

/* acc_read of an accessor that may be `width` or `width2` wide (0: only width); *got
 * says which. */
Status gltf_acc_read_either(Gltf *g, int a, int width, int width2, const char *use, double **out, size_t *count,
                            int *got)
{
    char jp[200];
    snprintf(jp, sizeof jp, "%s: accessor %d", use, a);
    const cJSON *acc = gltf_item_at(g, "accessors", a);
    long long ctype, n, off;
    int view;
    Status st = gltf_get_int(g, acc, "componentType", -1, 5120, 5126, jp, &ctype);
    if (!st) st = gltf_get_int(g, acc, "count", -1, 1, (long long)CLPT_MAX_FILE_BYTES, jp, &n);
    if (!st) st = gltf_get_int(g, acc, "byteOffset", 0, 0, (long long)CLPT_MAX_FILE_BYTES, jp, &off);
    if (!st) st = gltf_get_index(g, acc, "bufferView", 0, "bufferViews", jp, &view);
    if (st) return st;
    if (!comp_size(ctype)) return gltf_bad(g, jp, "componentType is not one glTF defines");
    const cJSON *type = cJSON_GetObjectItemCaseSensitive(acc, "type");
    int tw = cJSON_IsString(type) ? type_width(type->valuestring) : 0;
    if (tw != width && (!width2 || tw != width2)) {
        static const char *const names[] = { "SCALAR", "VEC2", "VEC3", "VEC4" };
        char what[80];
        if (width2)
            snprintf(what, sizeof what, "type must be %s or %s here", names[width - 1], names[width2 - 1]);
        else
            snprintf(what, sizeof what, "type must be %s here", names[width - 1]);
        return gltf_bad(g, jp, what);
    }
    width = tw;
    *got = tw;
    int normalized = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(acc, "normalized"));
    const cJSON *sparse = cJSON_GetObjectItemCaseSensitive(acc, "sparse");
    uint64_t esz = (uint64_t)comp_size(ctype) * (uint64_t)width;
    Buf vb = { NULL, 0, 0, NULL };
    size_t stride = 0;
    if (view >= 0) {
        if ((st = gltf_view_bytes(g, view, &vb, &stride))) return st;
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
        if (!sparse) return gltf_bad(g, jp, "has neither a bufferView nor sparse values");
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


/* ------------------------------------------------------------------ the file */

static const char *const supported_ext[] = {
    "KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_ior",
    "KHR_materials_transmission", "KHR_materials_clearcoat", "KHR_texture_transform",
    "KHR_materials_volume", "KHR_materials_specular", "KHR_materials_sheen", "EXT_mesh_gpu_instancing",
    "KHR_materials_diffuse_transmission", "KHR_materials_volume_scatter",
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
    for (const cJSON *e = gltf_first_of(req); e; e = e->next, i++) {
        if (cJSON_IsString(e) && !ext_supported(e->valuestring))
            return error_set(g->err, ST_INPUT, "%s: extensionsRequired[%d]: the file requires the extension '%s', "
                             "which clpt does not support", g->path, i, e->valuestring);
    }
    const cJSON *used = cJSON_GetObjectItemCaseSensitive(g->root, "extensionsUsed");
    for (const cJSON *e = gltf_first_of(used); e; e = e->next) {
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

Status gltf_open(Gltf *g, const char *data, size_t len)
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
        return gltf_bad(g, "asset.version", "missing or not 2.x (clpt reads glTF 2.0)");
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
    return ST_OK;
}

/* The node tree placed, and the camera asked for found. */
Status gltf_place(Gltf *g)
{
    Status st = gltf_scene_walk(g);
    if (st) return st;
    if (g->view && g->view->camera && !g->view->has_camera)
        return error_set(g->err, ST_INPUT, "%s: no camera '%s' (give a camera's index or its or its node's name)",
                         g->path, g->view->camera);
    return ST_OK;
}

void gltf_close(Gltf *g)
{
    cJSON_Delete(g->root);
    for (int i = 0; i < g->n_bufs; i++) free(g->bufs[i].owned);
    free(g->bufs);
    free(g->mats);
    free(g->tex);
    free(g->visited);
    free(g->placed);
    strmap_free(&g->buffer_files);
    strmap_free(&g->image_sources[0]);
    strmap_free(&g->image_sources[1]);
    for (int i = 0; i < T_N; i++) free(g->t[i].item);
    memset(g, 0, sizeof *g);
}

void gltf_init(Gltf *g, const char *path, Scene *s, const MeshOptions *o, GltfView *view, Error *err)
{
    memset(g, 0, sizeof *g);
    g->path = path;
    g->s = s;
    g->err = err;
    g->o = o;
    g->view = view;
    g->default_mat = NO_INDEX;
    g->reading_buffer = -1;
    g->camera_node = g->camera_index = -1;
    if (view) view->has_camera = 0;
}

Status gltf_parse(const char *path, const char *data, size_t len, Scene *s, const MeshOptions *o, GltfView *view,
                  Error *err)
{
    Gltf g;
    gltf_init(&g, path, s, o, view, err);
    Status st = gltf_open(&g, data, len);
    if (!st) st = gltf_place(&g);
    if (view) view->has_lights = g.has_lights;
    gltf_close(&g);
    return st;
}
