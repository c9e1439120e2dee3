/* device.c — listing, selecting and opening devices. */
#include "device/device.h"

#include "base/fault.h"
#include "device/ocl.h"
#include "device/scalar_paths.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

Status device_list(DeviceDesc **out, size_t *n, char *warning, size_t warning_size, Error *err)
{
    OclDeviceInfo *ocl = NULL;
    size_t n_ocl = 0;
    Error ocl_err = { 0 };
    if (warning_size) warning[0] = '\0';
    if (ocl_enumerate(&ocl, &n_ocl, &ocl_err) != ST_OK) {
        snprintf(warning, warning_size, "OpenCL devices unavailable: %s", ocl_err.msg);
        error_clear(&ocl_err);
        n_ocl = 0;
    }
    DeviceDesc *all = calloc(n_ocl + 1, sizeof *all);
    if (!all) {
        free(ocl);
        return error_set(err, ST_INTERNAL, "out of memory listing devices");
    }
    for (size_t i = 0; i < n_ocl; i++) {
        DeviceDesc *d = &all[i];
        const OclDeviceInfo *o = &ocl[i];
        d->kind = DEVICE_OPENCL;
        d->index = (unsigned)i;
        snprintf(d->name, sizeof d->name, "%s", o->name);
        d->type = ((o->type & CL_DEVICE_TYPE_CPU) ? DEVICE_TYPE_CPU : 0u) |
                  ((o->type & CL_DEVICE_TYPE_GPU) ? DEVICE_TYPE_GPU : 0u) |
                  ((o->type & CL_DEVICE_TYPE_ACCELERATOR) ? DEVICE_TYPE_ACCELERATOR : 0u);
        d->type_name = ocl_device_type_name(o->type);
        d->compute_units = o->compute_units;
        d->global_mem = o->global_mem;
        d->max_alloc = o->max_alloc;
        fault_device_memory((unsigned)i, &d->global_mem, &d->max_alloc);
        snprintf(d->platform_name, sizeof d->platform_name, "%s", o->platform_name);
        snprintf(d->driver_version, sizeof d->driver_version, "%s", o->driver_version);
        d->ocl_platform = o->platform;
        d->ocl_device = o->id;
        d->ocl_platform_index = o->platform_index;
        d->ocl_device_index = o->device_index;
    }
    DeviceDesc *scalar = &all[n_ocl];
    scalar->kind = DEVICE_SCALAR;
    scalar->index = (unsigned)n_ocl;
    snprintf(scalar->name, sizeof scalar->name, "scalar");
    scalar->type = DEVICE_TYPE_CPU;
    scalar->type_name = "CPU";
    free(ocl);
    *out = all;
    *n = n_ocl + 1;
    return ST_OK;
}

static void format_bytes(unsigned long long b, char *buf, size_t size)
{
    if (b >= (1ull << 30)) snprintf(buf, size, "%.1f GiB", (double)b / (double)(1ull << 30));
    else snprintf(buf, size, "%.0f MiB", (double)b / (double)(1ull << 20));
}

void device_list_print(FILE *f, const DeviceDesc *all, size_t n)
{
    fprintf(f, "%-3s %-8s %-6s %-5s %-10s %s\n", "#", "kind", "type", "units", "memory", "name (platform, driver)");
    for (size_t i = 0; i < n; i++) {
        const DeviceDesc *d = &all[i];
        char mem[32];
        if (d->kind == DEVICE_OPENCL) {
            format_bytes(d->global_mem, mem, sizeof mem);
            fprintf(f, "%-3u %-8s %-6s %-5u %-10s %s (%s, %s)\n", d->index, "opencl", d->type_name,
                    d->compute_units, mem, d->name, d->platform_name, d->driver_version);
        } else {
            long cores = sysconf(_SC_NPROCESSORS_ONLN);
            long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
            format_bytes(pages > 0 && page > 0 ? (unsigned long long)pages * (unsigned long long)page : 0,
                         mem, sizeof mem);
            /* which of its builds this processor runs (scalar_paths.h) */
            const char *isa_name = scalar_paths_isa_name(scalar_paths_isa_usable());
            char isa[32] = "";
            if (*isa_name) snprintf(isa, sizeof isa, " for %s", isa_name);
            /* no index: it is chosen by name (--device scalar), see select_item */
            fprintf(f, "%-3s %-8s %-6s %-5ld %-10s scalar C device (the kernels compiled as C%s, one thread per "
                    "core)\n", "-", "scalar", "CPU", cores > 0 ? cores : 1, mem, isa);
        }
    }
}

static int contains_ci(const char *hay, const char *needle)
{
    size_t n = strlen(needle);
    for (; *hay; hay++) {
        size_t i = 0;
        while (i < n && hay[i] && tolower((unsigned char)hay[i]) == tolower((unsigned char)needle[i])) i++;
        if (i == n) return 1;
    }
    return n == 0;
}

static int is_index(const char *s)
{
    if (!*s) return 0;
    for (; *s; s++)
        if (!isdigit((unsigned char)*s)) return 0;
    return 1;
}

static void add_choice(size_t *chosen, size_t *n, size_t index)
{
    for (size_t i = 0; i < *n; i++)
        if (chosen[i] == index) return;
    chosen[(*n)++] = index;
}

static Status no_such_device(const char *item, const DeviceDesc *all, size_t n, Error *err)
{
    char list[700] = "";
    size_t used = 0;
    for (size_t i = 0; i < n && used < sizeof list - 1; i++) {
        int w = all[i].kind == DEVICE_SCALAR
                    ? snprintf(list + used, sizeof list - used, "%s'scalar'", i ? "; " : "")
                    : snprintf(list + used, sizeof list - used, "%s%u: %s", i ? "; " : "", all[i].index, all[i].name);
        if (w < 0) break;
        used += (size_t)w;
    }
    return error_set(err, ST_USAGE, "no device matches '%s'; the devices are: %s (see --list-devices)",
                     item, list);
}

/* Adds the devices one item of --device names. */
static Status select_item(const char *item, const DeviceDesc *all, size_t n, size_t *chosen, size_t *k,
                          Error *err)
{
    size_t before = *k;
    if (is_index(item)) {
        /* An index names an OpenCL device only. The scalar device, listed last, would
         * otherwise have the index of the first OpenCL device a machine lacks: a job
         * asking for `--device 0` on a machine without OpenCL rendered on the scalar
         * device without a word. It is named 'scalar'. */
        unsigned long idx = strtoul(item, NULL, 10);
        size_t n_ocl = 0;
        while (n_ocl < n && all[n_ocl].kind == DEVICE_OPENCL) n_ocl++;
        if (n_ocl == 0)
            return error_set(err, ST_USAGE, "--device %s: there is no OpenCL device %s: no OpenCL device was found "
                             "(see --list-devices); the scalar device is --device scalar", item, item);
        if (idx >= n_ocl) return no_such_device(item, all, n, err);
        add_choice(chosen, k, idx);
        return ST_OK;
    }
    int matched = 0;
    for (size_t i = 0; i < n; i++) {
        int m;
        if (strcmp(item, "all") == 0) m = 1;
        else if (strcmp(item, "scalar") == 0) m = all[i].kind == DEVICE_SCALAR;
        else if (strcmp(item, "gpu") == 0) m = all[i].kind == DEVICE_OPENCL && (all[i].type & DEVICE_TYPE_GPU);
        else if (strcmp(item, "cpu") == 0) m = all[i].kind == DEVICE_OPENCL && (all[i].type & DEVICE_TYPE_CPU);
        else m = contains_ci(all[i].name, item) ||
                 (all[i].kind == DEVICE_OPENCL && contains_ci(all[i].platform_name, item));
        if (m) { add_choice(chosen, k, i); matched = 1; }
    }
    if (!matched && *k == before) return no_such_device(item, all, n, err);
    return ST_OK;
}

Status device_select(const char *spec, const DeviceDesc *all, size_t n, size_t **chosen_out,
                     size_t *n_chosen, Error *err)
{
    size_t *chosen = calloc(n, sizeof *chosen);
    if (!chosen) return error_set(err, ST_INTERNAL, "out of memory");
    size_t k = 0;
    if (!spec || !*spec) {
        for (size_t i = 0; i < n; i++)
            if (all[i].kind == DEVICE_OPENCL && (all[i].type & DEVICE_TYPE_GPU)) add_choice(chosen, &k, i);
        if (k == 0)
            for (size_t i = 0; i < n; i++)
                if (all[i].kind == DEVICE_OPENCL && (all[i].type & DEVICE_TYPE_CPU)) add_choice(chosen, &k, i);
        if (k == 0) add_choice(chosen, &k, n - 1);   /* the scalar device is always last */
        *chosen_out = chosen;
        *n_chosen = k;
        return ST_OK;
    }
    char *copy = malloc(strlen(spec) + 1);
    if (!copy) {
        free(chosen);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    strcpy(copy, spec);
    Status st = ST_OK;
    /* split by hand: strtok would skip empty items, and "," or "gpu,,cpu" is a typo to
     * report, not a request for the default devices */
    for (char *item = copy, *next; item; item = next) {
        char *comma = strchr(item, ',');
        next = comma ? comma + 1 : NULL;
        if (comma) *comma = '\0';
        while (isspace((unsigned char)*item)) item++;
        size_t len = strlen(item);
        while (len && isspace((unsigned char)item[len - 1])) item[--len] = '\0';
        if (len == 0) {
            st = error_set(err, ST_USAGE, "--device '%s' has an empty item; expected a comma-separated list "
                           "of indices, 'all', 'gpu', 'cpu', 'scalar' or device names", spec);
            break;
        }
        st = select_item(item, all, n, chosen, &k, err);
        if (st != ST_OK) break;
    }
    free(copy);
    if (st != ST_OK) {
        free(chosen);
        return st;
    }
    *chosen_out = chosen;
    *n_chosen = k;
    return ST_OK;
}

/* The default choice's groups, in the order it tries them; accelerators and custom
 * devices are never chosen by default. */
enum { GROUP_GPU, GROUP_CPU, GROUP_SCALAR, GROUP_NONE };

static int default_group(const DeviceDesc *d)
{
    if (d->kind == DEVICE_SCALAR) return GROUP_SCALAR;
    if (d->type & DEVICE_TYPE_GPU) return GROUP_GPU;
    if (d->type & DEVICE_TYPE_CPU) return GROUP_CPU;
    return GROUP_NONE;
}

Status device_select_fallback(const DeviceDesc *all, size_t n, size_t failed, size_t **chosen_out,
                              size_t *n_chosen, Error *err)
{
    size_t *chosen = calloc(n ? n : 1, sizeof *chosen);
    if (!chosen) return error_set(err, ST_INTERNAL, "out of memory");
    size_t k = 0;
    for (int g = default_group(&all[failed]) + 1; g < GROUP_NONE && k == 0; g++)
        for (size_t i = 0; i < n; i++)
            if (default_group(&all[i]) == g) add_choice(chosen, &k, i);
    *chosen_out = chosen;
    *n_chosen = k;
    return ST_OK;
}

Status device_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err)
{
    if (desc->kind == DEVICE_SCALAR) return device_scalar_open(desc, cfg, out, err);
    return device_ocl_open(desc, cfg, out, err);
}

void device_close(Device *d)
{
    if (d) d->ops->destroy(d);
}

/* The X-macro helpers that turn a line of kernels/scene_buffers.h into a buffer's
 * address: a ONE buffer is held by value, a MANY buffer is a pointer already. */
#define SCENE_DATA_ONE_(ds, name) ((const void *)&(ds)->name)
#define SCENE_DATA_MANY_(ds, name) ((const void *)(ds)->name)

SceneBufferBytes device_scene_buffer(const DeviceScene *ds, unsigned b)
{
    switch (b) {
#define SCENE_BUFFER_CASE_(kind, Type, name, count, what)                                   \
    case SCENE_BUF_##name:                                                                  \
        return (SceneBufferBytes){ SCENE_DATA_##kind##_(ds, name), (size_t)(count) * sizeof(Type), what };
        SCENE_BUFFERS(SCENE_BUFFER_CASE_)
#undef SCENE_BUFFER_CASE_
    default:
        return (SceneBufferBytes){ NULL, 0, "no such scene buffer" };
    }
}

void device_scene_view(const DeviceScene *ds, SceneView *view)
{
#define SCENE_VIEW_SET_(kind, Type, name, count, what) view->name = (const Type *)SCENE_DATA_##kind##_(ds, name);
    SCENE_BUFFERS(SCENE_VIEW_SET_)
#undef SCENE_VIEW_SET_
    view->time = 0.0f;
}
/* No device of the default choice could be used: warns, and replaces *chosen with the
 * next group of the default order; 0 when none is left. */
static int device__fall_back(const DeviceDesc *all, size_t n_all, size_t **chosen, size_t *n_chosen, const Error *last,
                             DeviceWarn warn, void *warn_ctx)
{
    size_t *next = NULL, n_next = 0;
    Error err = { 0 };
    if (device_select_fallback(all, n_all, (*chosen)[0], &next, &n_next, &err) != ST_OK || n_next == 0) {
        free(next);
        error_clear(&err);
        return 0;
    }
    if (*n_chosen == 1) {   /* several were each reported as they were dropped */
        warn(warn_ctx, last->msg);
        if (last->detail) fprintf(stderr, "%s\n", last->detail);
    }
    fprintf(stderr, "clpt: warning: the default device%s cannot be used; falling back to device %u '%s'%s\n",
            *n_chosen > 1 ? "s" : "", all[next[0]].index, all[next[0]].name, n_next > 1 ? " and others" : "");
    free(*chosen);
    *chosen = next;
    *n_chosen = n_next;
    return 1;
}

/* Opens each chosen device into devs and gives it the scene; returns how many could be
 * used. A device that fails is dropped with a warning when there are others; *last
 * keeps the last failure. */
static size_t device__open_chosen(const DeviceDesc *all, const size_t *chosen, size_t n_chosen, const DeviceConfig *cfg,
                                  const DeviceScene *ds, Device **devs, Error *last, DeviceWarn warn, void *warn_ctx)
{
    size_t n = 0;
    for (size_t i = 0; i < n_chosen; i++) {
        Device *d = NULL;
        error_clear(last);
        Status st = device_open(&all[chosen[i]], cfg, &d, last);
        if (st == ST_OK) st = d->ops->load_scene(d, ds, last);
        if (st == ST_OK) {
            devs[n++] = d;
            continue;
        }
        device_close(d);
        if (n_chosen > 1) {
            warn(warn_ctx, last->msg);
            if (last->detail) fprintf(stderr, "%s\n", last->detail);
            fprintf(stderr, "clpt: warning: device %u '%s' dropped; rendering with the others\n",
                    all[chosen[i]].index, all[chosen[i]].name);
        }
    }
    return n;
}

Status device_update_all(Device **devs, size_t n, const DeviceScene *ds, Error *err)
{
    for (size_t i = 0; i < n; i++) {
        Status st = devs[i]->ops->update_params(devs[i], &ds->params, ds->pixel_list, err);
        if (st) return st;
    }
    return ST_OK;
}

Status device_open_all(const char *spec, const DeviceConfig *cfg, const DeviceScene *ds, DeviceWarn warn,
                       void *warn_ctx, Device ***out, size_t *n_out, Error *err)
{
    DeviceDesc *all = NULL;
    size_t n_all = 0, *chosen = NULL, n_chosen = 0;
    char warning[1100];
    Status st = device_list(&all, &n_all, warning, sizeof warning, err);
    if (st) return st;
    /* said here, once per run, and only when it decides where the render goes */
    if (warning[0]) warn(warn_ctx, warning);
    else if (n_all == 1 && !spec)
        warn(warn_ctx, "no OpenCL platform found (none installed, or OCL_ICD_VENDORS names none): "
                       "rendering on the scalar device");
    if ((st = device_select(spec, all, n_all, &chosen, &n_chosen, err))) {
        free(all);
        return st;
    }
    Device **devs = calloc(n_all, sizeof *devs);
    if (!devs) {
        free(all);
        free(chosen);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    size_t n = 0;
    Error last = { 0 };
    int by_default = !spec || !spec[0];
    do
        n = device__open_chosen(all, chosen, n_chosen, cfg, ds, devs, &last, warn, warn_ctx);
    while (n == 0 && by_default && device__fall_back(all, n_all, &chosen, &n_chosen, &last, warn, warn_ctx));
    free(all);
    free(chosen);
    if (n == 0) {
        free(devs);
        if (n_chosen == 1) {
            *err = last;   /* the one device's own error, with its build log */
            return last.status ? last.status : ST_DEVICE;
        }
        error_clear(&last);
        return error_set(err, ST_DEVICE, "none of the %zu chosen devices could be used", n_chosen);
    }
    error_clear(&last);
    *out = devs;
    *n_out = n;
    return ST_OK;
}

