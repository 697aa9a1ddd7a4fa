/* fovea — stage clocks: a stage's time and its serial part (see stage_time.h). */
#include "core/parallel.h"
#include "core/stage_time.h"

fv_stage_clock fv_stage_clock_now(void)
{
    fv_stage_clock c;
    /* the region clock first: a region open now counts up to a moment no later than `wall` */
    c.parallel = fv_region_parallel_ms();
    c.wall = fv_time_ms();
    return c;
}

void fv_stage_add(fv_stats *s, const char *stage, fv_stage_clock from, fv_stage_clock to)
{
    const double wall = to.wall - from.wall;
    double serial = wall - (to.parallel - from.parallel);
    /* the two clocks are read a moment apart: keep the share within the stage */
    if (serial < 0.0) serial = 0.0;
    if (serial > wall) serial = wall;
    fv_stats_add_ms(s, stage, wall);
    fv_stats_add_serial_ms(s, stage, serial);
}

void fv_stage_stop(fv_stats *s, const char *stage, fv_stage_clock from) { fv_stage_add(s, stage, from, fv_stage_clock_now()); }
