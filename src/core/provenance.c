/* fovea — provenance: what build and which machine made a result (fovea/provenance.h).
 *
 * The commit and dirty flag come from fv_build_info.h, generated on every build by
 * cmake/build_info.cmake; this is the only file that includes it, so a new commit recompiles this
 * file alone. The Embree version is the one in the headers the library was compiled against.
 */
#include <embree3/rtcore_config.h>
#include <stdio.h>
#include <string.h>
#include <sys/utsname.h>
#include <time.h>
#include <unistd.h>
#include "core/parallel.h"
#include "core/provenance_json.h"
#include "fv_build_info.h"

void fv_build_info_get(fv_build_info *out)
{
    out->version = FOVEA_VERSION_STRING;
    out->commit = FV_BUILD_COMMIT;
    out->dirty = FV_BUILD_DIRTY;
    out->build_type = FV_BUILD_TYPE[0] ? FV_BUILD_TYPE : "unknown";
    out->compiler = FV_BUILD_COMPILER;
    out->embree = RTC_VERSION_STRING;
    out->sanitize = FV_BUILD_SANITIZE != 0;
}

/* The first "model name" line of /proc/cpuinfo (x86 and most Linux ports carry it). */
static void cpu_model(char *out, size_t n)
{
    snprintf(out, n, "unknown");
    FILE *f = fopen("/proc/cpuinfo", "r");
    if (!f) return;
    char line[512];
    while (fgets(line, sizeof line, f)) {
        if (strncmp(line, "model name", 10) != 0) continue;
        const char *v = strchr(line, ':');
        if (!v) continue;
        v++;
        while (*v == ' ' || *v == '\t') v++;
        size_t len = strcspn(v, "\r\n");
        if (len > 0) snprintf(out, n, "%.*s", (int)len, v);
        break;
    }
    fclose(f);
}

void fv_host_info_get(fv_host_info *out)
{
    memset(out, 0, sizeof *out);
    cpu_model(out->cpu, sizeof out->cpu);
    long c = sysconf(_SC_NPROCESSORS_ONLN);
    out->cores = c > 0 ? (int)c : 1;
    struct utsname u;
    if (uname(&u) == 0) snprintf(out->os, sizeof out->os, "%.60s %.60s", u.sysname, u.release);
    else snprintf(out->os, sizeof out->os, "unknown");
}

int fv_threads_used(int requested) { return fv_thread_count(requested); }

void fv_utc_now(char *out, int n)
{
    time_t t = time(NULL);
    struct tm tm;
    if (n <= 0) return;
    if (!gmtime_r(&t, &tm) || strftime(out, (size_t)n, "%Y-%m-%dT%H:%M:%SZ", &tm) == 0) snprintf(out, (size_t)n, "unknown");
}

cJSON *fv_provenance_json(int threads_requested)
{
    fv_build_info b;
    fv_host_info h;
    fv_build_info_get(&b);
    fv_host_info_get(&h);
    char date[32];
    fv_utc_now(date, sizeof date);
    cJSON *o = cJSON_CreateObject();
    if (!o) return NULL;
    cJSON_AddStringToObject(o, "fovea_version", b.version);
    cJSON_AddStringToObject(o, "commit", b.commit);
    if (b.dirty < 0) cJSON_AddNullToObject(o, "dirty");
    else cJSON_AddBoolToObject(o, "dirty", b.dirty);
    cJSON_AddStringToObject(o, "build_type", b.build_type);
    cJSON_AddBoolToObject(o, "sanitize", b.sanitize);
    cJSON_AddStringToObject(o, "compiler", b.compiler);
    cJSON_AddStringToObject(o, "embree", b.embree);
    cJSON_AddStringToObject(o, "cpu", h.cpu);
    cJSON_AddNumberToObject(o, "cores", h.cores);
    cJSON_AddStringToObject(o, "os", h.os);
    cJSON_AddNumberToObject(o, "threads_requested", threads_requested);
    cJSON_AddNumberToObject(o, "threads", fv_threads_used(threads_requested));
    cJSON_AddStringToObject(o, "date", date);
    return o;
}

void fv_provenance_line(char *out, size_t n)
{
    fv_build_info b;
    fv_build_info_get(&b);
    snprintf(out, n, "fovea %s, commit %.12s%s, %s%s, %s, Embree %s", b.version, b.commit,
             b.dirty > 0 ? " (dirty)" : b.dirty < 0 ? "" : "", b.build_type, b.sanitize ? " + sanitizers" : "", b.compiler, b.embree);
}
