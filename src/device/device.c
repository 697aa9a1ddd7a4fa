/* fovea — device names, the choice `auto` makes, and whether a device can run here (see
 * fovea/device.h). Whether CUDA is there is asked of the CUDA backend only in a build that has it
 * (FOVEA_HAVE_CUDA); elsewhere the answer is the build's.
 */
#include <stdio.h>
#include <string.h>
#include "device/cuda_backend.h"
#include "fovea/device.h"
#include "fovea/technique.h"

const char *fv_device_name(fv_device d)
{
    switch (d) {
    case FV_DEVICE_PORTABLE: return "portable";
    case FV_DEVICE_CUDA: return "cuda";
    default: return "cpu";
    }
}

bool fv_device_available(fv_device d, char *why, size_t why_len)
{
    if (d != FV_DEVICE_CUDA) return true;
    char msg[256] = "";
    bool ok = fv_cuda_probe(msg, sizeof msg);
    if (!ok && why && why_len) snprintf(why, why_len, "%s", msg);
    return ok;
}

fv_status fv_device_parse(const char *name, const char *method, fv_device *out, fv_error *err)
{
    if (!name) name = "(null)";
    if (!strcmp(name, "cpu")) *out = FV_DEVICE_CPU;
    else if (!strcmp(name, "portable")) *out = FV_DEVICE_PORTABLE;
    else if (!strcmp(name, "cuda")) *out = FV_DEVICE_CUDA;
    else if (!strcmp(name, "auto")) {
        int i = method ? fv_technique_index(method) : -1;
        bool has = !method || (i >= 0 && fv_technique_has_device(i, FV_DEVICE_CUDA));
        *out = has && fv_device_available(FV_DEVICE_CUDA, NULL, 0) ? FV_DEVICE_CUDA : FV_DEVICE_CPU;
    } else {
        return fv_error_set(err, FV_ERR_INVALID, "device '%s' is not one of cpu, portable, cuda, auto", name);
    }
    return FV_OK;
}
