/* fovea — per-frame stage timings and counters (see include/fovea/stats.h). */
#include <stdio.h>
#include <string.h>
#include <time.h>
#include "fovea/stats.h"

void fv_stats_clear(fv_stats *s) { memset(s, 0, sizeof *s); }

static void add(fv_stat_entry *e, int *n, const char *name, double v)
{
    for (int i = 0; i < *n; i++)
        if (strcmp(e[i].name, name) == 0) {
            e[i].value += v;
            return;
        }
    if (*n >= FV_STATS_MAX) return;
    snprintf(e[*n].name, sizeof e[*n].name, "%s", name);
    e[*n].value = v;
    (*n)++;
}

static double get(const fv_stat_entry *e, int n, const char *name)
{
    for (int i = 0; i < n; i++)
        if (strcmp(e[i].name, name) == 0) return e[i].value;
    return 0.0;
}

void fv_stats_add_ms(fv_stats *s, const char *stage, double ms)
{
    if (s) add(s->stage, &s->n_stages, stage, ms);
}
void fv_stats_add_count(fv_stats *s, const char *counter, double v)
{
    if (s) add(s->counter, &s->n_counters, counter, v);
}
void fv_stats_add_serial_ms(fv_stats *s, const char *stage, double ms)
{
    if (s) add(s->serial, &s->n_serial, stage, ms);
}
double fv_stats_get_serial_ms(const fv_stats *s, const char *stage)
{
    for (int i = 0; i < s->n_serial; i++)
        if (strcmp(s->serial[i].name, stage) == 0) return s->serial[i].value;
    return -1.0;
}
double fv_stats_get_ms(const fv_stats *s, const char *stage) { return get(s->stage, s->n_stages, stage); }
double fv_stats_get_count(const fv_stats *s, const char *counter) { return get(s->counter, s->n_counters, counter); }

double fv_time_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}
