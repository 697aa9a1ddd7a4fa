/* fovea — the progress callback every long call takes (a render, the driver's frames, the
 * library's parallel loops).
 *
 * Its own header, below everything that takes one, so that the core's loops, which report
 * progress and cancel, need nothing of the frame that carries it (fovea/frame.h).
 */
#ifndef FOVEA_PROGRESS_H
#define FOVEA_PROGRESS_H

#include <stdbool.h>

#ifdef __cplusplus
extern "C" {
#endif

/* Called now and then with the fraction of the eye's work done, never from two threads at once.
 * Returning false cancels the render: the technique stops soon and returns FV_ERR_CANCELLED. */
typedef bool (*fv_progress_fn)(void *user, double fraction);

#ifdef __cplusplus
}
#endif
#endif
