/* fovea — the Visual-Polar device frame's tables that follow the gaze (gaze_tables.h). */
#include "technique/vpolar/gaze_tables.h"
#include "technique/vpolar/vpolar_kernels.h"

void fv_vp_gaze_tables_forget(fv_vp_gaze_tables *t)
{
    t->rows_made = t->mask_made = t->lut_made[0] = t->lut_made[1] = false;
}

static bool view_same(const fv_kvp_view *a, const fv_kvp_view *b)
{
    return a->gx == b->gx && a->gy == b->gy && a->rho_max == b->rho_max && a->log_rho_max == b->log_rho_max;
}

/* a and b give the same entries (on one grid and screen: a new one forgets both). */
static bool radial_same(const fv_kvp_radial *a, const fv_kvp_radial *b)
{
    return view_same(&a->view, &b->view) && a->step == b->step && a->n == b->n && a->blur == b->blur && a->px_per_deg == b->px_per_deg &&
           a->scale == b->scale && a->fovea_deg == b->fovea_deg && a->ramp_deg == b->ramp_deg && a->sigma_px == b->sigma_px;
}

/* A buffer that holds at least `bytes`; *made false when it had to be made anew (its contents lost). */
static fv_status table_ensure(fv_backend *b, fv_buffer *buf, size_t bytes, bool *made, const char *what, fv_error *err)
{
    void *was = buf->p;
    const fv_status s = fv_buffer_ensure(b, buf, bytes, what, err);
    if (buf->p != was) *made = false;
    return s;
}

/* The mask: the rows' angles once per grid, then each column's bound and its cells when the view
 * (or the reach) moved. */
static fv_status queue_mask(fv_backend *b, fv_vp_gaze_tables *t, const fv_kvp_space *sp, const fv_kvp_view *view, const int *col_h, float reach,
                            fv_error *err)
{
    const int gw = sp->gw, gh = sp->gh;
    bool cols_made = true;
    fv_status s;
    if ((s = table_ensure(b, &t->rows, 2 * (size_t)gh * sizeof(float), &t->rows_made, "the on-screen mask", err)) != FV_OK ||
        (s = table_ensure(b, &t->cols, (size_t)gw * sizeof(fv_kvp_onscreen_col), &cols_made, "the on-screen mask", err)) != FV_OK ||
        (s = table_ensure(b, &t->mask, (size_t)gw * (size_t)gh, &t->mask_made, "the on-screen mask", err)) != FV_OK)
        return s;
    if (!t->rows_made) {
        const fv_vp_rows_args ra = {gh, (float *)t->rows.p};
        t->mask_made = false;
        if ((s = fv_backend_launch(b, &fv_vp_rows_kernel, gh, 1, &ra, NULL, err)) != FV_OK) return s;
        t->rows_made = true;
    }
    if (cols_made && t->mask_made && view_same(&t->mask_view, view) && t->mask_reach == reach) return FV_OK;
    fv_vp_onscreen_args oa;
    oa.space = *sp;
    oa.view = *view;
    oa.reach = reach;
    oa.col_h = col_h;
    oa.row_cs = (const float *)t->rows.p;
    oa.col = (fv_kvp_onscreen_col *)t->cols.p;
    oa.mask = (uint8_t *)t->mask.p;
    t->mask_made = false;
    if ((s = fv_backend_launch(b, &fv_vp_onscreen_col_kernel, gw, 1, &oa, NULL, err)) != FV_OK ||
        (s = fv_backend_launch(b, &fv_vp_onscreen_kernel, gw, gh, &oa, NULL, err)) != FV_OK)
        return s;
    t->mask_made = true;
    t->mask_view = *view, t->mask_reach = reach;
    return FV_OK;
}

fv_status fv_vp_gaze_tables_queue(fv_backend *b, fv_vp_gaze_tables *t, const fv_kvp_space *space, const fv_kvp_view *view, const int *col_h,
                                  bool onscreen, float reach, const fv_kvp_radial *radial, fv_error *err)
{
    fv_status s;
    t->mask_on = false;
    t->lut_now = t->lut_prev;
    for (int i = 0; i < 2; i++)
        if ((s = table_ensure(b, &t->lut[i], (size_t)radial->n * 3 * sizeof(float), &t->lut_made[i], "the radial table", err)) != FV_OK) return s;
    if (onscreen) {
        if ((s = queue_mask(b, t, space, view, col_h, reach, err)) != FV_OK) return s;
        t->mask_on = true;
    }
    /* A gaze that stays: the previous frame's table is this one's. */
    int now = t->lut_prev;
    if (!(t->lut_made[now] && radial_same(&t->lut_of[now], radial))) {
        now ^= 1;
        if (!(t->lut_made[now] && radial_same(&t->lut_of[now], radial))) {
            fv_vp_radial_args ra;
            ra.t = *radial;
            ra.t.table = (float *)t->lut[now].p;
            t->lut_made[now] = false;
            if ((s = fv_backend_launch(b, &fv_vp_radial_kernel, radial->n, 1, &ra, NULL, err)) != FV_OK) return s;
            t->lut_made[now] = true;
            t->lut_of[now] = *radial;
        }
    }
    t->lut_now = now;
    return FV_OK;
}

const uint8_t *fv_vp_gaze_tables_mask(const fv_vp_gaze_tables *t)
{
    return t->mask_on ? (const uint8_t *)t->mask.p : NULL;
}

const float *fv_vp_gaze_tables_lut(const fv_vp_gaze_tables *t)
{
    return (const float *)t->lut[t->lut_now].p;
}

const float *fv_vp_gaze_tables_prev_lut(const fv_vp_gaze_tables *t)
{
    return t->lut_made[t->lut_prev] ? (const float *)t->lut[t->lut_prev].p : NULL;
}

void fv_vp_gaze_tables_advance(fv_vp_gaze_tables *t)
{
    t->lut_prev = t->lut_now;
}

void fv_vp_gaze_tables_release(fv_backend *b, fv_vp_gaze_tables *t)
{
    fv_buffer *const m[] = {&t->rows, &t->cols, &t->mask, &t->lut[0], &t->lut[1]};
    for (size_t i = 0; i < sizeof m / sizeof m[0]; i++) fv_buffer_release(b, m[i]);
    fv_vp_gaze_tables_forget(t);
}
