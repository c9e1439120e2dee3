/* display.c — the tev viewer's IPC protocol over TCP (see display.h). */
#include "render/display.h"

#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "base/bytes.h"

#define CONNECT_MS 2000
#define TILE 128   /* pixels a side: about 200 KB a packet, as tev's own client sends */

struct Display {
    int fd;                 /* -1 once the connection is dropped */
    char name[256];
    char address[300];
    unsigned width, height;
    unsigned char *packet;  /* one tile's packet, reused */
};

/* ------------------------------------------------------------------ the address */

/* Splits HOST:PORT (HOST may be [IPv6]) into host and port; 0 with the reason in err. */
static int address_split(const char *address, char *host, size_t size, char *port, Error *err)
{
    const char *colon = strrchr(address, ':');
    const char *h = address, *h_end = colon;
    if (address[0] == '[') {
        const char *close = strchr(address, ']');
        if (!close || close[1] != ':')
            return error_set(err, ST_USAGE, "--display-server '%s': an IPv6 address is written [ADDRESS]:PORT",
                             address), 0;
        h = address + 1, h_end = close, colon = close + 1;
    }
    if (!colon || h_end == h)
        return error_set(err, ST_USAGE, "--display-server expects HOST:PORT (tev listens on localhost:14158), "
                         "got '%s'", address), 0;
    char *end = NULL;
    errno = 0;
    long p = strtol(colon + 1, &end, 10);
    if (!colon[1] || *end || errno || p < 1 || p > 65535)
        return error_set(err, ST_USAGE, "--display-server '%s': the port must be a number 1..65535", address), 0;
    if ((size_t)(h_end - h) >= size) return error_set(err, ST_USAGE, "--display-server: host name too long"), 0;
    memcpy(host, h, (size_t)(h_end - h));
    host[h_end - h] = '\0';
    snprintf(port, 8, "%ld", p);
    return 1;
}

Status display_check_address(const char *address, Error *err)
{
    char host[256], port[8];
    return address_split(address, host, sizeof host, port, err) ? ST_OK : ST_USAGE;
}

/* ------------------------------------------------------------------ connecting */

/* A non-blocking connect that waits CONNECT_MS at most; the socket, or -1 with errno. */
static int connect_within(const struct addrinfo *ai)
{
    int fd = socket(ai->ai_family, ai->ai_socktype | SOCK_CLOEXEC, ai->ai_protocol);
    if (fd < 0) return -1;
    int flags = fcntl(fd, F_GETFL);
    fcntl(fd, F_SETFL, flags | O_NONBLOCK);
    int rc = connect(fd, ai->ai_addr, ai->ai_addrlen), e = errno;
    if (rc != 0 && e == EINPROGRESS) {
        struct pollfd p = { fd, POLLOUT, 0 };
        socklen_t len = sizeof e;
        rc = poll(&p, 1, CONNECT_MS) == 1 && getsockopt(fd, SOL_SOCKET, SO_ERROR, &e, &len) == 0 && e == 0 ? 0 : -1;
        if (rc != 0 && e == EINPROGRESS) e = ETIMEDOUT;
    }
    if (rc != 0) {
        close(fd);
        errno = e;
        return -1;
    }
    /* blocking again, but a send that stalls a second fails (display_update drops the
     * connection): a viewer that stops reading never holds the render's thread */
    fcntl(fd, F_SETFL, flags);
    struct timeval tv = { 1, 0 };
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
    return fd;
}

static int connect_to(const char *address, Error *err)
{
    char host[256], port[8];
    if (!address_split(address, host, sizeof host, port, err)) return -1;
    struct addrinfo hints, *list = NULL;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    int g = getaddrinfo(host, port, &hints, &list);
    if (g != 0) {
        error_set(err, ST_IO, "cannot reach the display server '%s': %s", address, gai_strerror(g));
        return -1;
    }
    int fd = -1, e = 0;
    for (const struct addrinfo *ai = list; ai && fd < 0; ai = ai->ai_next)
        if ((fd = connect_within(ai)) < 0) e = errno;
    freeaddrinfo(list);
    if (fd < 0) error_set(err, ST_IO, "cannot reach the display server '%s': %s", address, strerror(e));
    return fd;
}

/* ------------------------------------------------------------------ packets */

/* A packet under construction: bytes appended at `n`, the length filled in at the end. */
typedef struct {
    unsigned char *b;
    size_t n;
} Packet;

static void put_u8(Packet *p, unsigned v) { p->b[p->n++] = (unsigned char)v; }
static void put_i32(Packet *p, int32_t v) { bytes_put_le32(p->b + p->n, (uint32_t)v); p->n += 4; }
static void put_i64(Packet *p, int64_t v) { bytes_put_le64(p->b + p->n, (uint64_t)v); p->n += 8; }
static void put_str(Packet *p, const char *s)
{
    size_t k = strlen(s) + 1;
    memcpy(p->b + p->n, s, k);
    p->n += k;
}
static void put_f32(Packet *p, float v)
{
    uint32_t u;
    memcpy(&u, &v, 4);
    bytes_put_le32(p->b + p->n, u);
    p->n += 4;
}

/* The packet's length into its first 4 bytes, and the whole of it to the socket
 * (MSG_NOSIGNAL: a closed connection is an error here, not SIGPIPE). */
static Status packet_send(Display *d, Packet *p, Error *err)
{
    bytes_put_le32(p->b, (uint32_t)p->n);
    for (size_t sent = 0; sent < p->n;) {
        ssize_t w = send(d->fd, p->b + sent, p->n - sent, MSG_NOSIGNAL);
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            int e = errno;
            close(d->fd);
            d->fd = -1;
            return error_set(err, ST_IO, "the display server '%s' %s; the render goes on without it", d->address,
                             e == EAGAIN || e == EWOULDBLOCK ? "stopped reading" : "went away");
        }
        sent += (size_t)w;
    }
    return ST_OK;
}

static const char *const channels[3] = { "R", "G", "B" };

/* CloseImage (an earlier run's image of this name), then CreateImage. */
static Status send_create(Display *d, Error *err)
{
    Packet p = { d->packet, 4 };
    put_u8(&p, DISPLAY_CLOSE_IMAGE);
    put_str(&p, d->name);
    Status st = packet_send(d, &p, err);
    if (st) return st;
    p.n = 4;
    put_u8(&p, DISPLAY_CREATE_IMAGE);
    put_u8(&p, 1);   /* grab focus: the render is what the user is waiting to see */
    put_str(&p, d->name);
    put_i32(&p, (int32_t)d->width);
    put_i32(&p, (int32_t)d->height);
    put_i32(&p, 3);
    for (int c = 0; c < 3; c++) put_str(&p, channels[c]);
    return packet_send(d, &p, err);
}

/* UpdateImage of the tile at (x0, y0), tw x th pixels, RGB interleaved. */
static Status send_tile(Display *d, const float *rgb, unsigned x0, unsigned y0, unsigned tw, unsigned th, Error *err)
{
    Packet p = { d->packet, 4 };
    put_u8(&p, DISPLAY_UPDATE_IMAGE);
    put_u8(&p, 0);
    put_str(&p, d->name);
    put_i32(&p, 3);
    for (int c = 0; c < 3; c++) put_str(&p, channels[c]);
    put_i32(&p, (int32_t)x0);
    put_i32(&p, (int32_t)y0);
    put_i32(&p, (int32_t)tw);
    put_i32(&p, (int32_t)th);
    for (int c = 0; c < 3; c++) put_i64(&p, c);
    for (int c = 0; c < 3; c++) put_i64(&p, 3);
    for (unsigned y = y0; y < y0 + th; y++)
        for (size_t i = ((size_t)y * d->width + x0) * 3u, e = i + (size_t)tw * 3u; i < e; i++) put_f32(&p, rgb[i]);
    return packet_send(d, &p, err);
}

/* ------------------------------------------------------------------ the interface */

Status display_open(const char *address, const char *name, unsigned width, unsigned height, Display **out,
                    Error *err)
{
    *out = NULL;
    Display *d = calloc(1, sizeof *d);
    /* the largest packet: a tile, with the name and channel names twice over */
    size_t cap = 4096 + sizeof d->name + (size_t)TILE * TILE * 3u * 4u;
    if (!d || !(d->packet = malloc(cap))) {
        free(d);
        return error_set(err, ST_INTERNAL, "out of memory");
    }
    snprintf(d->name, sizeof d->name, "%s", name);
    snprintf(d->address, sizeof d->address, "%s", address);
    d->width = width;
    d->height = height;
    d->fd = connect_to(address, err);
    /* a malformed address is the user's to fix (ST_USAGE, checked before the render
     * too); anything else about the server is ST_IO */
    Status st = d->fd >= 0 ? send_create(d, err) : display_check_address(address, NULL) ? ST_USAGE : ST_IO;
    if (st != ST_OK) {
        display_close(d);
        return st;
    }
    *out = d;
    return ST_OK;
}

Status display_update(Display *d, const float *rgb, Error *err)
{
    Status st = ST_OK;
    for (unsigned y = 0; d && d->fd >= 0 && y < d->height && st == ST_OK; y += TILE)
        for (unsigned x = 0; x < d->width && st == ST_OK; x += TILE)
            st = send_tile(d, rgb, x, y, d->width - x < TILE ? d->width - x : TILE,
                           d->height - y < TILE ? d->height - y : TILE, err);
    return st;
}

void display_close(Display *d)
{
    if (!d) return;
    if (d->fd >= 0) close(d->fd);
    free(d->packet);
    free(d);
}
