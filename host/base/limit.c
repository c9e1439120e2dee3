/* limit.c — the checks of limit.h. */
#include "base/limit.h"

Status limit_count(const char *where, const char *what, uint64_t count, uint64_t min_bytes,
                   uint64_t bytes_left, Error *err)
{
    uint64_t max = min_bytes ? bytes_left / min_bytes : UINT64_MAX;
    if (count <= max) return ST_OK;
    return error_set(err, ST_INPUT,
                     "%s: the header declares %llu %s, but the %llu bytes after it hold at most "
                     "%llu (at least %llu bytes each): the file is truncated or the count is wrong",
                     where, (unsigned long long)count, what, (unsigned long long)bytes_left,
                     (unsigned long long)max, (unsigned long long)min_bytes);
}

int limit_bytes(uint64_t count, uint64_t size, size_t *bytes)
{
    if (size && count > (uint64_t)SIZE_MAX / size) return -1;
    *bytes = (size_t)(count * size);
    return 0;
}

Status limit_pixels(uint64_t width, uint64_t height, Status status, const char *where, Error *err)
{
    if (width <= CLPT_MAX_IMAGE_SIDE && height <= CLPT_MAX_IMAGE_SIDE &&
        width * height <= CLPT_MAX_PIXELS)
        return ST_OK;
    return error_set(err, status,
                     "%s: an image of %llux%llu pixels is larger than clpt renders (at most "
                     "%u pixels, as in 16384x8192, and %d on each side)",
                     where, (unsigned long long)width, (unsigned long long)height,
                     CLPT_MAX_PIXELS, CLPT_MAX_IMAGE_SIDE);
}

Status limit_file_size(const char *path, uint64_t bytes, Error *err)
{
    if (bytes <= CLPT_MAX_FILE_BYTES) return ST_OK;
    return error_set(err, ST_INPUT, "'%s' is %llu bytes, more than the %llu (4 GiB) clpt reads from one file",
                     path, (unsigned long long)bytes, (unsigned long long)CLPT_MAX_FILE_BYTES);
}
