/* fovea — where a method runs: the CPU path (Embree, SIMD, OpenMP), the portable backend (the
 * kernels written once for CPU and GPU, run on the CPU over the flat scene; what CI tests them
 * with) or an NVIDIA GPU through CUDA (docs/gpu.md).
 *
 * A method declares the devices it has; fv_technique_create reads the parameter `device` (what the
 * CLI's --device sets) and refuses, in one line, a device the method lacks, a CUDA device in a build
 * without CUDA, or one on a machine without a GPU.
 */
#ifndef FOVEA_DEVICE_H
#define FOVEA_DEVICE_H

#include <stdbool.h>
#include <stddef.h>
#include "fovea/export.h"
#include "fovea/status.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum fv_device {
    FV_DEVICE_CPU = 0,      /* every method: Embree and the CPU's own code */
    FV_DEVICE_PORTABLE = 1, /* the device kernels on the CPU (OpenMP over pixels, the flat BVH) */
    FV_DEVICE_CUDA = 2      /* the device kernels on an NVIDIA GPU */
} fv_device;

/* "cpu", "portable", "cuda". */
FV_API const char *fv_device_name(fv_device d);

/* "cpu" | "portable" | "cuda" | "auto" -> a device for method `method` (NULL: any): auto is CUDA
 * when this build has CUDA, a GPU is present and the method has a CUDA version, else the CPU.
 * FV_ERR_INVALID for any other name. Availability is not checked here (fv_device_available). */
FV_API fv_status fv_device_parse(const char *name, const char *method, fv_device *out, fv_error *err);

/* True when this build and machine can run on d now; otherwise false and, in why (may be NULL), the
 * reason as a clause: "fovea was built without CUDA", "no CUDA device (...)". */
FV_API bool fv_device_available(fv_device d, char *why, size_t why_len);

/* What fv_technique_create does with the parameter device=NAME for method `method`, without a
 * scene: the resolved device in *out, or FV_ERR_INVALID with one line when the name is not a
 * device, the method does not run there (the line lists the methods that do), or this build or
 * machine cannot run it ("built without CUDA", "no CUDA device"). For early checks in tools. */
FV_API fv_status fv_device_check(const char *method, const char *name, fv_device *out, fv_error *err);

/* True when method i (fv_technique_name) runs on device d. */
FV_API bool fv_technique_has_device(int i, fv_device d);

#ifdef __cplusplus
}
#endif
#endif
