/* fovea — a film's buffers on a device backend (device/backend.h): the kernels write a frame's
 * colour and auxiliary buffers into device memory, the frame queues their download into pinned
 * staging buffers (a copy that does not block the host, unlike one into the film's own pageable
 * memory), and after the frame's wait the staging buffers are handed to the film. On portable
 * the kernels write the film's own buffers and nothing is copied.
 *
 * The staging buffers are double: frame N reads back into slot N mod 2, so frame N+1 can be queued
 * (and its read-back with it) before frame N's copy has completed and been delivered (a sequence's
 * submit/collect, technique/class.h). Both slots are made in a sequence's first frame (frame 0):
 * the device buffers are shared by the slots (the queue runs frame N's download before frame
 * N+1's kernels), so only the pinned ones are doubled.
 *
 * Only the buffers the host film has are made and read back. The buffers only grow, so a sequence
 * allocates in its first frame and never after.
 */
#ifndef FV_DEVICE_FILM_DEVICE_H
#define FV_DEVICE_FILM_DEVICE_H

#include "device/backend.h"
#include "fovea/film.h"

enum { FV_FILM_DEVICE_BUFFERS = 6 }; /* colour, depth, normal, albedo, position, id */
enum { FV_FILM_DEVICE_SLOTS = 2 };   /* frames in flight: the one being collected, the next */

typedef struct fv_film_device {
    fv_buffer dev[FV_FILM_DEVICE_BUFFERS];
    fv_buffer stage[FV_FILM_DEVICE_SLOTS][FV_FILM_DEVICE_BUFFERS]; /* pinned */
    fv_buffer display, display_stage[FV_FILM_DEVICE_SLOTS];       /* a display-only film's RGBA8 */
} fv_film_device;

/* *dev receives the views the kernels write for host's n pixels (the buffers host has, else NULL). */
fv_status fv_film_device_views(fv_backend *b, fv_film_device *f, const fv_film_views *host, size_t n, fv_film_views *dev, fv_error *err);
/* Queues the download of those buffers into slot's staging buffers (after the frame's kernels);
 * the first call makes both slots' staging buffers. */
fv_status fv_film_device_download(fv_backend *b, fv_film_device *f, int slot, const fv_film_views *host, size_t n, fv_error *err);
/* After the wait for slot's frame: its downloaded pixels into host's buffers. */
void fv_film_device_deliver(fv_backend *b, const fv_film_device *f, int slot, const fv_film_views *host, size_t n);
/* The same for a whole film, its display output included: a display-only film
 * (fv_film_set_display) has its colour converted to RGBA8 on the device (device/display_kernels.h)
 * after the frame's kernels, and that is read back (4 bytes a pixel) instead of the float colour;
 * the delivery then marks the film's display output filled. Any other film as the views above. */
fv_status fv_film_device_download_film(fv_backend *b, fv_film_device *f, int slot, fv_film *film, fv_error *err);
void fv_film_device_deliver_film(fv_backend *b, const fv_film_device *f, int slot, fv_film *film);
void fv_film_device_release(fv_backend *b, fv_film_device *f);

#endif
