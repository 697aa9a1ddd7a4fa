/* fovea — FV_API marks what libfovea.so exports. The library is compiled with
 * -fvisibility=hidden, so every function without FV_API stays private to it. */
#ifndef FOVEA_EXPORT_H
#define FOVEA_EXPORT_H

#if defined(__GNUC__) || defined(__clang__)
#define FV_API __attribute__((visibility("default")))
#else
#define FV_API
#endif

#endif
