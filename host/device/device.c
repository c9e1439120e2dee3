/* device.c — listing, selecting and opening devices. */
#include "device/device.h"

#include "base/fault.h"

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
        all[i].kind = DEVICE_OPENCL;
        all[i].index = (unsigned)i;
        all[i].ocl = ocl[i];
        fault_device_memory((unsigned)i, &all[i].ocl.global_mem, &all[i].ocl.max_alloc);
        snprintf(all[i].name, sizeof all[i].name, "%s", ocl[i].name);
    }
    all[n_ocl].kind = DEVICE_SCALAR;
    all[n_ocl].index = (unsigned)n_ocl;
    snprintf(all[n_ocl].name, sizeof all[n_ocl].name, "scalar");
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
            format_bytes(d->ocl.global_mem, mem, sizeof mem);
            fprintf(f, "%-3u %-8s %-6s %-5u %-10s %s (%s, %s)\n", d->index, "opencl",
                    ocl_device_type_name(d->ocl.type), d->ocl.compute_units, mem, d->name,
                    d->ocl.platform_name, d->ocl.driver_version);
        } else {
            long cores = sysconf(_SC_NPROCESSORS_ONLN);
            long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
            format_bytes(pages > 0 && page > 0 ? (unsigned long long)pages * (unsigned long long)page : 0,
                         mem, sizeof mem);
            fprintf(f, "%-3u %-8s %-6s %-5ld %-10s %s\n", d->index, "scalar", "CPU", cores > 0 ? cores : 1,
                    mem, "scalar C device (the kernels compiled as C, one thread per core)");
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
        int w = snprintf(list + used, sizeof list - used, "%s%u: %s", i ? "; " : "", all[i].index, all[i].name);
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
        unsigned long idx = strtoul(item, NULL, 10);
        if (idx >= n) return no_such_device(item, all, n, err);
        add_choice(chosen, k, idx);
        return ST_OK;
    }
    int matched = 0;
    for (size_t i = 0; i < n; i++) {
        int m;
        if (strcmp(item, "all") == 0) m = 1;
        else if (strcmp(item, "scalar") == 0) m = all[i].kind == DEVICE_SCALAR;
        else if (strcmp(item, "gpu") == 0) m = all[i].kind == DEVICE_OPENCL && (all[i].ocl.type & CL_DEVICE_TYPE_GPU);
        else if (strcmp(item, "cpu") == 0) m = all[i].kind == DEVICE_OPENCL && (all[i].ocl.type & CL_DEVICE_TYPE_CPU);
        else m = contains_ci(all[i].name, item) ||
                 (all[i].kind == DEVICE_OPENCL && contains_ci(all[i].ocl.platform_name, item));
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
            if (all[i].kind == DEVICE_OPENCL && (all[i].ocl.type & CL_DEVICE_TYPE_GPU)) add_choice(chosen, &k, i);
        if (k == 0)
            for (size_t i = 0; i < n; i++)
                if (all[i].kind == DEVICE_OPENCL && (all[i].ocl.type & CL_DEVICE_TYPE_CPU)) add_choice(chosen, &k, i);
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

Status device_open(const DeviceDesc *desc, const DeviceConfig *cfg, Device **out, Error *err)
{
    if (desc->kind == DEVICE_SCALAR) return device_scalar_open(desc, cfg, out, err);
    return device_ocl_open(desc, cfg, out, err);
}

void device_close(Device *d)
{
    if (d) d->ops->destroy(d);
}
