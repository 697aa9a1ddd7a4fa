/* fovea — a device name read for a method (fv_device_parse, fovea/device.h): the one place where
 * `auto` is resolved. It needs the registry (which methods have a CUDA path), so it lives above
 * device/, which knows no technique. fv_device_check (technique/registry.c) then refuses a device
 * the method does not run on, or one that is not here. */
#include <string.h>
#include "fovea/device.h"
#include "fovea/technique.h"

fv_status fv_device_parse(const char *name, const char *method, fv_device *out, fv_error *err)
{
    if (!name) name = "(null)";
    if (!strcmp(name, "cpu")) *out = FV_DEVICE_CPU;
    else if (!strcmp(name, "portable")) *out = FV_DEVICE_PORTABLE;
    else if (!strcmp(name, "cuda")) *out = FV_DEVICE_CUDA;
    else if (!strcmp(name, "auto")) {
        /* cuda where the method has a CUDA path and a GPU is here, else the CPU */
        int i = method ? fv_technique_index(method) : -1;
        bool has = !method || (i >= 0 && fv_technique_has_device(i, FV_DEVICE_CUDA));
        *out = has && fv_device_available(FV_DEVICE_CUDA, NULL, 0) ? FV_DEVICE_CUDA : FV_DEVICE_CPU;
    } else {
        return fv_error_set(err, FV_ERR_INVALID, "device '%s' is not one of cpu, portable, cuda, auto", name);
    }
    return FV_OK;
}
