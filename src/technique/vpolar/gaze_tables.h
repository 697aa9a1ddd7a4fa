/* fovea — the tables of the Visual-Polar device frame that follow the gaze (Foveated Real-Time Path
 * Tracing in Visual-Polar Space, Sec. 3.2: the space is placed at the gaze every frame), computed
 * on the device by technique/vpolar/vpolar_kernels.h's kernels over technique/vpolar/kvp_tables.h, the
 * functions the CPU's space.c and vp_pipeline.c run, so both compute the same values:
 *
 *   the on-screen mask    a cell a thread (after its column's bound), the cells some pixel within
 *                         `reach` of the screen sees: the trace skips the others (offscreen=skip),
 *                         the reprojection and the denoiser always;
 *   the radial table      an entry a thread: column, φ-mip level and blur sigma by the distance
 *                         from the gaze, which the map reads; two buffers used in turn, since the
 *                         reprojection reads the previous frame's.
 *
 * Each is kept with what it was computed for and queued again only when that changed (a frame whose
 * gaze stays launches nothing here), so nothing of them crosses the bus, and the host does none of
 * their work (the mask was a million cells an eye on one CPU thread at 1440x1600). Buffers only
 * grow (fv_buffer), and the first frame makes room for both radial tables.
 */
#ifndef FV_TECHNIQUE_VPOLAR_GAZE_TABLES_H
#define FV_TECHNIQUE_VPOLAR_GAZE_TABLES_H

#include <stdbool.h>
#include <stdint.h>
#include "device/backend.h"
#include "technique/vpolar/kvp_space.h"
#include "technique/vpolar/kvp_tables.h"

typedef struct fv_vp_gaze_tables {
    fv_buffer rows, cols, mask; /* the full-height rows' angles, the mask's column bounds, the mask */
    bool rows_made, mask_made;  /* false: nothing yet, or the grid or a buffer is new */
    bool mask_on;               /* this frame has a mask */
    fv_kvp_view mask_view;      /* what the mask holds */
    float mask_reach;
    fv_buffer lut[2];           /* the radial tables, this frame's and the previous one's, in turn */
    bool lut_made[2];
    fv_kvp_radial lut_of[2];    /* what each holds (its table pointer unused) */
    int lut_prev;               /* the one the previous frame mapped with */
    int lut_now;                /* the one this frame maps with (fv_vp_gaze_tables_queue) */
} fv_vp_gaze_tables;

/* A new grid or screen: every table is computed again at the next queue. */
void fv_vp_gaze_tables_forget(fv_vp_gaze_tables *t);

/* Queues what this frame's tables need on b: when onscreen, the mask of space's grid (col_h: gw
 * heights on b, NULL: every column full) at view for reach; the radial table radial describes (its
 * table ignored) into lut_now, the buffer the previous frame did not map with unless one of the
 * two holds it already. */
fv_status fv_vp_gaze_tables_queue(fv_backend *b, fv_vp_gaze_tables *t, const fv_kvp_space *space, const fv_kvp_view *view, const int *col_h,
                                  bool onscreen, float reach, const fv_kvp_radial *radial, fv_error *err);

/* Device pointers after a queue: the mask (NULL without one), this frame's radial table, the
 * previous frame's (NULL when there is none). */
const uint8_t *fv_vp_gaze_tables_mask(const fv_vp_gaze_tables *t);
const float *fv_vp_gaze_tables_lut(const fv_vp_gaze_tables *t);
const float *fv_vp_gaze_tables_prev_lut(const fv_vp_gaze_tables *t);

/* The frame mapped with lut_now: it is the next frame's previous table. */
void fv_vp_gaze_tables_advance(fv_vp_gaze_tables *t);

void fv_vp_gaze_tables_release(fv_backend *b, fv_vp_gaze_tables *t);

#endif
