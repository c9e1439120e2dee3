/*
 * display.h — --display-server HOST:PORT: the image, as it converges, sent to the tev
 * image viewer (https://github.com/Tom94/tev) over TCP in tev's documented IPC
 * protocol, as pbrt-v4's --display-server does. docs/display-server.md.
 *
 * Each packet is a little-endian uint32 length (the whole packet's, these 4 bytes
 * included), a type byte and its fields; strings end with a NUL. clpt sends:
 *   CloseImage  (2): name                       an image of the same name left by an
 *                                               earlier run is replaced, not doubled
 *   CreateImage (4): grab focus, name, width, height, channel count, channel names
 *   UpdateImage (6, tev's third version): grab focus, name, channel count, channel
 *               names, x, y, width, height, the channels' int64 offsets, then their
 *               int64 strides (in floats), then the tile's floats
 * and at the end closes the connection, leaving the image open in tev.
 *
 * The display is a help, never a condition: a server that cannot be reached, stops
 * reading or goes away is said once (as a warning) and the render goes on without it.
 */
#ifndef CLPT_DISPLAY_H
#define CLPT_DISPLAY_H

#include "base/status.h"

typedef struct Display Display;

/* tev's packet types (its IpcPacket::EType). */
enum { DISPLAY_CLOSE_IMAGE = 2, DISPLAY_CREATE_IMAGE = 4, DISPLAY_UPDATE_IMAGE = 6 };

/* Checks that `address` is HOST:PORT (a name, an IPv4 address or [IPv6], and a port
 * 1..65535): ST_USAGE with the reason otherwise. Nothing is connected. */
Status display_check_address(const char *address, Error *err);

/* Connects to `address` (2 s at most) and creates the image `name`, width x height,
 * channels R, G, B. ST_IO when the server cannot be reached (the caller warns and goes
 * on); *out is then NULL. */
Status display_open(const char *address, const char *name, unsigned width, unsigned height, Display **out,
                    Error *err);

/* Sends the whole image (width x height x 3 floats, top row first) in tiles. A send
 * that fails or stalls for a second drops the connection: the first such failure is
 * returned once as ST_IO (to warn about), later calls do nothing and return ST_OK. */
Status display_update(Display *d, const float *rgb, Error *err);

/* Closes the connection (the image stays in tev); NULL is fine. */
void display_close(Display *d);

#endif /* CLPT_DISPLAY_H */
