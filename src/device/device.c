/* fovea — device names and whether a device can run here (see fovea/device.h). Whether CUDA is
 * there is asked of the CUDA backend (device/backend.h), which in a build without it says so.
 * Which device `auto` picks for a method is the technique registry's (technique/registry.c, the
 * one place that knows which methods run where). */
#include <stdio.h>
#include "device/backend.h"
#include "fovea/device.h"

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
    bool ok = fv_backend_cuda_probe(msg, sizeof msg);
    if (!ok && why && why_len) snprintf(why, why_len, "%s", msg);
    return ok;
}
