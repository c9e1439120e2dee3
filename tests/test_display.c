/*
 * test_display.c — --display-server (render/display.h): a listener in this test stands
 * in for the tev viewer. It receives tev's packets in order (CloseImage, CreateImage
 * with the size and R, G, B, then UpdateImage tiles), the image the updates leave is the
 * written one bit for bit, and the connection is closed at the end. A server that goes
 * away, or was never there, costs a warning and nothing else; a malformed address is a
 * usage error.
 */
#include "harness.h"

#include <netinet/in.h>
#include <pthread.h>
#include <stdint.h>
#include <sys/socket.h>

#include "base/bytes.h"
#include "cli_util.h"
#include "image_metrics.h"
#include "render/display.h"

#define W 300
#define H 200

/* What the listener saw. */
typedef struct {
    int fd;                   /* the listening socket */
    int hang_up;              /* close the connection after the CreateImage packet */
    int types[64], n_types, n_packets;
    int malformed;            /* a packet that does not parse as tev's */
    char name[256];
    int32_t width, height, channels;
    float *image;             /* W x H x 3, as the updates leave it */
    int eof;                  /* the connection was closed by clpt */
} Listener;

/* Reads exactly n bytes; 0 at the end of the stream. */
static int read_all(int fd, unsigned char *b, size_t n)
{
    for (size_t got = 0; got < n;) {
        ssize_t r = recv(fd, b + got, n - got, 0);
        if (r <= 0) return 0;
        got += (size_t)r;
    }
    return 1;
}

/* A NUL-terminated string at *at, moving *at past it; NULL when it runs off the end. */
static const char *get_str(const unsigned char *b, size_t n, size_t *at)
{
    const char *s = (const char *)b + *at;
    size_t k = strnlen(s, n - *at);
    if (*at + k >= n) return NULL;
    *at += k + 1;
    return s;
}

/* An UpdateImage packet (tev's third version) into l->image. */
static void parse_update(Listener *l, const unsigned char *b, size_t n)
{
    size_t at = 1;
    const char *name = get_str(b, n, &at);
    if (!name || strcmp(name, l->name) || at + 4 > n) { l->malformed = 1; return; }
    int32_t nc = (int32_t)bytes_get_le32(b + at);
    at += 4;
    for (int c = 0; c < nc; c++)
        if (!get_str(b, n, &at)) { l->malformed = 1; return; }
    if (nc != 3 || at + 16 + 48 > n) { l->malformed = 1; return; }
    int32_t x = (int32_t)bytes_get_le32(b + at), y = (int32_t)bytes_get_le32(b + at + 4);
    int32_t w = (int32_t)bytes_get_le32(b + at + 8), h = (int32_t)bytes_get_le32(b + at + 12);
    at += 16;
    for (int c = 0; c < 3; c++)
        if (bytes_get_le64(b + at + 8u * c) != (uint64_t)c || bytes_get_le64(b + at + 24 + 8u * c) != 3u) l->malformed = 1;
    at += 48;
    if (x < 0 || y < 0 || w <= 0 || h <= 0 || x + w > W || y + h > H || at + (size_t)w * h * 12u != n) {
        l->malformed = 1;
        return;
    }
    for (int32_t j = 0; j < h; j++)
        for (int32_t i = 0; i < w * 3; i++) {
            uint32_t u = bytes_get_le32(b + at + ((size_t)j * w * 3 + i) * 4u);
            memcpy(&l->image[((size_t)(y + j) * W + x) * 3u + i], &u, 4);
        }
}

static void parse_packet(Listener *l, const unsigned char *b, size_t n)
{
    size_t at = 1;
    if (l->n_types < 64) l->types[l->n_types++] = b[0];
    l->n_packets++;
    if (b[0] == DISPLAY_CLOSE_IMAGE) {
        const char *name = get_str(b, n, &at);
        if (!name || at != n) l->malformed = 1;
    } else if (b[0] == DISPLAY_CREATE_IMAGE) {
        at = 2;   /* after grab focus */
        const char *name = get_str(b, n, &at);
        if (!name || at + 12 > n) { l->malformed = 1; return; }
        snprintf(l->name, sizeof l->name, "%s", name);
        l->width = (int32_t)bytes_get_le32(b + at);
        l->height = (int32_t)bytes_get_le32(b + at + 4);
        l->channels = (int32_t)bytes_get_le32(b + at + 8);
        at += 12;
        static const char *const want[3] = { "R", "G", "B" };
        for (int c = 0; c < l->channels && c < 3; c++) {
            const char *ch = get_str(b, n, &at);
            if (!ch || strcmp(ch, want[c])) l->malformed = 1;
        }
        if (at != n) l->malformed = 1;
    } else if (b[0] == DISPLAY_UPDATE_IMAGE && n > 1) {
        parse_update(l, b + 1, n - 1);
    } else {
        l->malformed = 1;
    }
}

static void *listen_thread(void *arg)
{
    Listener *l = arg;
    int c = accept(l->fd, NULL, NULL);
    if (c < 0) return NULL;
    unsigned char head[4];
    while (read_all(c, head, 4)) {
        uint32_t n = bytes_get_le32(head);
        unsigned char *b = n > 5 && n < (1u << 26) ? malloc(n - 4) : NULL;
        if (!b || !read_all(c, b, n - 4)) {
            l->malformed = 1;
            free(b);
            break;
        }
        parse_packet(l, b, n - 4);
        free(b);
        if (l->hang_up && l->types[l->n_types - 1] == DISPLAY_CREATE_IMAGE) break;
    }
    if (!l->hang_up) l->eof = 1;
    close(c);
    return NULL;
}

/* A listener on 127.0.0.1 at a free port; its port, or 0. */
static int listener_start(Listener *l, pthread_t *t)
{
    memset(l->types, 0, sizeof l->types);
    l->n_types = l->n_packets = l->malformed = l->eof = 0;
    l->fd = socket(AF_INET, SOCK_STREAM, 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t len = sizeof a;
    if (l->fd < 0 || bind(l->fd, (struct sockaddr *)&a, sizeof a) || listen(l->fd, 1) ||
        getsockname(l->fd, (struct sockaddr *)&a, &len) || pthread_create(t, NULL, listen_thread, l))
        return 0;
    return ntohs(a.sin_port);
}

static void run_clpt(int port, const char *out, const char *spp, CliResult *r)
{
    char address[64];
    snprintf(address, sizeof address, "127.0.0.1:%d", port);
    const char *args[] = { "scenes/cornell-box.scene", "-q", "--width", "300", "--height", "200", "--spp", spp,
                           "--batch", "1", "--display-server", address, "-o", out, NULL };
    cli_run(args, r);
}

static CliResult result;

/* The packets in order, and the image they leave equal to the written PFM. */
static void test_stream_equals_output(void)
{
    Listener l = { .hang_up = 0 };
    l.image = calloc((size_t)W * H * 3u, sizeof *l.image);
    pthread_t t;
    int port = listener_start(&l, &t);
    CHECK(port > 0 && l.image);
    if (port <= 0 || !l.image) return;
    const char *out = TEST_TMP("clpt-test-display.pfm");
    run_clpt(port, out, "48", &result);
    pthread_join(t, NULL);
    close(l.fd);
    CHECK_MSG(result.status == 0, "%s", result.err);
    CHECK_MSG(!l.malformed, "a packet did not parse as tev's");
    CHECK(l.n_types >= 3 && l.types[0] == DISPLAY_CLOSE_IMAGE && l.types[1] == DISPLAY_CREATE_IMAGE);
    for (int i = 2; i < l.n_types; i++) CHECK(l.types[i] == DISPLAY_UPDATE_IMAGE);
    CHECK(!strcmp(l.name, "clpt-test-display.pfm"));
    CHECK(l.width == W && l.height == H && l.channels == 3);
    /* 6 tiles an update (128-pixel tiles over 300 x 200) */
    CHECK((l.n_packets - 2) % 6 == 0 && l.n_packets >= 8);
    CHECK(l.eof);
    unsigned w = 0, h = 0;
    float *img = metrics_read_pfm(out, &w, &h);
    CHECK(img && w == W && h == H);
    if (img) CHECK_MSG(!memcmp(img, l.image, (size_t)W * H * 3u * sizeof *img), "tev's image differs from the output");
    fprintf(stderr, "  %d packets (%d updates of the whole image)\n", l.n_packets, (l.n_packets - 2) / 6);
    free(img);
    free(l.image);
    unlink(out);
}

/* A viewer that goes away after CreateImage: the render goes on and writes its image;
 * at most one warning. */
static void test_lost_connection(void)
{
    Listener l = { .hang_up = 1 };
    pthread_t t;
    int port = listener_start(&l, &t);
    CHECK(port > 0);
    if (port <= 0) return;
    const char *out = TEST_TMP("clpt-test-display-lost.png");
    run_clpt(port, out, "16", &result);
    pthread_join(t, NULL);
    close(l.fd);
    CHECK_MSG(result.status == 0, "%s", result.err);
    CHECK(file_exists(out));
    const char *warn = strstr(result.err, "warning: the display server");
    CHECK_MSG(!warn || !strstr(warn + 1, "warning: the display server"), "%s", result.err);
    unlink(out);
}

/* Nobody listening: one warning naming the address, the image written, status 0. */
static void test_unreachable_server(void)
{
    Listener l = { .hang_up = 1 };
    pthread_t t;
    int port = listener_start(&l, &t);
    CHECK(port > 0);
    if (port <= 0) return;
    /* the port is now free again: nobody listens there */
    shutdown(l.fd, SHUT_RDWR);
    close(l.fd);
    pthread_join(t, NULL);
    const char *out = TEST_TMP("clpt-test-display-none.png");
    run_clpt(port, out, "4", &result);
    char want[200];
    snprintf(want, sizeof want, "clpt: warning: cannot reach the display server '127.0.0.1:%d': Connection refused\n",
             port);
    CHECK_MSG(result.status == 0, "%s", result.err);
    CHECK_MSG(!strcmp(result.err, want), "%s", result.err);
    CHECK(file_exists(out));
    unlink(out);
}

static void test_bad_address(void)
{
    Error err = { 0 };
    CHECK(display_check_address("localhost:14158", &err) == ST_OK);
    CHECK(display_check_address("[::1]:14158", &err) == ST_OK);
    CHECK(display_check_address("localhost", &err) == ST_USAGE);
    CHECK(display_check_address("host:0", &err) == ST_USAGE);
    CHECK(display_check_address("host:65536", &err) == ST_USAGE);
    CHECK(display_check_address(":14158", &err) == ST_USAGE);
    CHECK(display_check_address("::1:14158", &err) == ST_OK);   /* the last colon splits */
    error_clear(&err);
    const char *args[] = { "scenes/cornell-box.scene", "--display-server", "host:x", NULL };
    cli_run(args, &result);
    CHECK(result.status == 2);
    CHECK_MSG(strstr(result.err, "--display-server 'host:x': the port must be a number 1..65535"), "%s", result.err);
}

int main(void)
{
    RUN(test_bad_address);
    RUN(test_unreachable_server);
    RUN(test_stream_equals_output);
    RUN(test_lost_connection);
    return harness_report();
}
