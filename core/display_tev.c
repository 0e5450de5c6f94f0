/* display_tev.c: see display_tev.h. */
#include "display_tev.h"

#include <errno.h>
#include <netdb.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "array.h"

#define TEV_UPDATE_IMAGE 3
#define TEV_CREATE_IMAGE 4

struct display_tev {
    char host[256], port[16];
    int socket;                  /* -1: not connected */
    bool failed;                 /* a send failed: no more tries */
    bool warning_taken;
    char warning[512];
    char created[DISPLAY_TEV_NAME_MAX];   /* the image last created, "" none */
    uint8_t *packet;             /* the packet being built */
    size_t length, capacity;
};

rt_status display_tev_create(const char *address, display_tev **out, rt_error *error)
{
    *out = NULL;
    const char *colon = strrchr(address, ':');
    char *end = NULL;
    long port = colon != NULL ? strtol(colon + 1, &end, 10) : 0;
    if (colon == NULL || colon == address || (size_t)(colon - address) >= 256 || end == colon + 1 || *end != '\0'
        || port < 1 || port > 65535)
        return rt_error_set(error, RT_ERROR_INPUT, "DISPLAY: '%s' is not HOST:PORT (e.g. localhost:14158)", address);
    display_tev *display = calloc(1, sizeof *display);
    if (display == NULL)
        return rt_error_set(error, RT_ERROR_RUNTIME, "DISPLAY: out of memory");
    memcpy(display->host, address, (size_t)(colon - address));
    snprintf(display->port, sizeof display->port, "%ld", port);
    display->socket = -1;
    signal(SIGPIPE, SIG_IGN);
    *out = display;
    return RT_OK;
}

void display_tev_destroy(display_tev *display)
{
    if (display == NULL)
        return;
    if (display->socket >= 0)
        close(display->socket);
    free(display->packet);
    free(display);
}

bool display_tev_take_warning(display_tev *display, char *text, size_t size)
{
    if (!display->failed || display->warning_taken)
        return false;
    display->warning_taken = true;
    snprintf(text, size, "%s", display->warning);
    return true;
}

/* Marks the display failed with a warning saying what (the first one only). */
static bool fail(display_tev *display, const char *what)
{
    if (!display->failed)
        snprintf(display->warning, sizeof display->warning,
                 "the tev viewer at %s:%s %s; the render goes on without it", display->host, display->port, what);
    display->failed = true;
    if (display->socket >= 0)
        close(display->socket);
    display->socket = -1;
    return false;
}

/* Connects to the viewer (with a 3-second send timeout, as a stuck viewer must not stop
 * the render for long). */
static bool connect_viewer(display_tev *display)
{
    struct addrinfo hints = {0}, *found = NULL;
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    if (getaddrinfo(display->host, display->port, &hints, &found) != 0)
        return fail(display, "has a host name that does not resolve");
    for (struct addrinfo *a = found; a != NULL && display->socket < 0; a = a->ai_next) {
        int s = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (s < 0)
            continue;
        struct timeval timeout = {.tv_sec = 3};
        setsockopt(s, SOL_SOCKET, SO_SNDTIMEO, &timeout, sizeof timeout);
        if (connect(s, a->ai_addr, a->ai_addrlen) == 0)
            display->socket = s;
        else
            close(s);
    }
    freeaddrinfo(found);
    return display->socket >= 0 ? true : fail(display, "is not there (connection refused)");
}

/* Appends size bytes to the packet; false when memory runs out. */
static bool put(display_tev *display, const void *bytes, size_t size)
{
    if (!array_reserve((void **)&display->packet, &display->capacity, display->length + size, 1))
        return false;
    memcpy(display->packet + display->length, bytes, size);
    display->length += size;
    return true;
}

static bool put_int(display_tev *display, int32_t value) { return put(display, &value, sizeof value); }
static bool put_byte(display_tev *display, uint8_t value) { return put(display, &value, 1); }
static bool put_string(display_tev *display, const char *text) { return put(display, text, strlen(text) + 1); }

/* Starts a packet of type (its length is filled in by send_packet). */
static bool begin_packet(display_tev *display, uint8_t type)
{
    display->length = 0;
    return put_int(display, 0) && put_byte(display, type);
}

/* Sends the packet built, its length first; false (and failed) when the viewer is gone. */
static bool send_packet(display_tev *display)
{
    int32_t length = (int32_t)display->length;
    memcpy(display->packet, &length, sizeof length);
    size_t sent = 0;
    while (sent < display->length) {
        ssize_t n = send(display->socket, display->packet + sent, display->length - sent, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return fail(display, "went away");
        sent += (size_t)n;
    }
    return true;
}

bool display_tev_send(display_tev *display, const char *name, const rt_image *image)
{
    if (display->failed || image->channels < 3)
        return false;
    if (display->socket < 0 && !connect_viewer(display))
        return false;
    static const char *const channels[3] = {"R", "G", "B"};
    if (strcmp(display->created, name) != 0) {
        bool built = begin_packet(display, TEV_CREATE_IMAGE) && put_byte(display, 1) && put_string(display, name) &&
                     put_int(display, image->width) && put_int(display, image->height) && put_int(display, 3);
        for (int c = 0; c < 3 && built; c++)
            built = put_string(display, channels[c]);
        if (!built)
            return fail(display, "could not be sent to (out of memory)");
        if (!send_packet(display))
            return false;
        snprintf(display->created, sizeof display->created, "%s", name);
    }
    for (int y = 0; y < image->height; y += DISPLAY_TEV_TILE)
        for (int x = 0; x < image->width; x += DISPLAY_TEV_TILE) {
            int width = image->width - x < DISPLAY_TEV_TILE ? image->width - x : DISPLAY_TEV_TILE;
            int height = image->height - y < DISPLAY_TEV_TILE ? image->height - y : DISPLAY_TEV_TILE;
            for (int c = 0; c < 3; c++) {
                bool built = begin_packet(display, TEV_UPDATE_IMAGE) && put_byte(display, 0) &&
                             put_string(display, name) && put_string(display, channels[c]) && put_int(display, x) &&
                             put_int(display, y) && put_int(display, width) && put_int(display, height);
                for (int row = y; row < y + height && built; row++)
                    for (int column = x; column < x + width && built; column++) {
                        float value = image->pixels[((size_t)row * image->width + column) * image->channels + c];
                        built = put(display, &value, sizeof value);
                    }
                if (!built)
                    return fail(display, "could not be sent to (out of memory)");
                if (!send_packet(display))
                    return false;
            }
        }
    return true;
}
