/* The device backend's contract (device/backend.h), checked on one device: test_backend runs it on
 * the portable backend, tests/gpu/test_gpu_backend on CUDA (and, built against the simulator, on
 * the simulated runtime, whose own counts must then agree). Hand-worked figures: every byte and
 * call below is counted by hand from the calls made. */
#ifndef FV_TEST_BACKEND_CHECKS_H
#define FV_TEST_BACKEND_CHECKS_H

#include <math.h>
#include <string.h>
#include "device/backend.h"
#include "device/fill_kernels.h"

#define FV_BC_N 1000

static void fv_bc_expect(const fv_backend *b, const fv_backend_calls *from, const char *what, uint64_t waits, uint64_t pageable, uint64_t h2d,
                         uint64_t d2h, uint64_t allocs, uint64_t frees, uint64_t launches)
{
    fv_backend_calls now, d;
    fv_backend_calls_get(b, &now);
    fv_backend_calls_diff(&now, from, &d);
    if (d.host_waits != waits || d.pageable_copies != pageable || d.bytes_h2d != h2d || d.bytes_d2h != d2h || d.allocations != allocs ||
        d.frees != frees || d.launches != launches)
        fail_msg("%s on %s: waits %llu (want %llu), pageable %llu (%llu), h2d %llu (%llu), d2h %llu (%llu), allocs %llu (%llu), frees %llu (%llu), "
                 "launches %llu (%llu)",
                 what, fv_device_name(fv_backend_device(b)), (unsigned long long)d.host_waits, (unsigned long long)waits,
                 (unsigned long long)d.pageable_copies, (unsigned long long)pageable, (unsigned long long)d.bytes_h2d, (unsigned long long)h2d,
                 (unsigned long long)d.bytes_d2h, (unsigned long long)d2h, (unsigned long long)d.allocations, (unsigned long long)allocs,
                 (unsigned long long)d.frees, (unsigned long long)frees, (unsigned long long)d.launches, (unsigned long long)launches);
}

static void fv_backend_checks(fv_device device)
{
    fv_backend *b;
    fv_error err;
    if (fv_backend_create(device, &b, &err) != FV_OK) fail_msg("%s", err.msg);
    const bool gpu = device == FV_DEVICE_CUDA;
    fv_backend_calls c0;
    fv_backend_calls_get(b, &c0);

    /* buffers only grow: 400 bytes, then 200 (kept), then 800 (one free, one allocation) */
    fv_buffer buf = {0}, pin = {0};
    if (fv_buffer_ensure(b, &buf, 400, "a test buffer", &err) != FV_OK || fv_buffer_ensure(b, &buf, 200, "a test buffer", &err) != FV_OK)
        fail_msg("%s", err.msg);
    if (buf.cap != 400) fail_msg("a buffer of 400 bytes asked for 200 has %zu", buf.cap);
    fv_bc_expect(b, &c0, "a kept buffer", 0, 0, 0, 0, 1, 0, 0);
    if (fv_buffer_ensure(b, &buf, FV_BC_N * sizeof(float), "a test buffer", &err) != FV_OK) fail_msg("%s", err.msg);
    fv_bc_expect(b, &c0, "a grown buffer", 0, 0, 0, 0, 2, 1, 0);

    /* pinned memory is not device memory, and copies through it queue without waiting */
    if (fv_pinned_ensure(b, &pin, FV_BC_N * sizeof(float), "a test buffer", &err) != FV_OK) fail_msg("%s", err.msg);
    float *host = pin.p;
    for (int i = 0; i < FV_BC_N; i++) host[i] = (float)i;
    fv_backend_calls c1;
    fv_backend_calls_get(b, &c1);
    /* upload 1000 floats, overwrite [100, 600) with +inf by a launch, clear the first 8 bytes, read all back */
    const fv_fill_f32_args fa = {(float *)buf.p + 100, INFINITY};
    if (fv_backend_upload(b, buf.p, host, FV_BC_N * sizeof(float), "a test array", &err) != FV_OK ||
        fv_backend_launch(b, &fv_fill_f32_kernel, 500, 1, &fa, NULL, &err) != FV_OK ||
        fv_backend_clear(b, buf.p, 0, 2 * sizeof(float), "a test array", &err) != FV_OK)
        fail_msg("%s", err.msg);
    fv_backend_mark(b, 0);
    memset(host, 0, FV_BC_N * sizeof(float));
    if (fv_backend_download(b, host, buf.p, FV_BC_N * sizeof(float), "a test array", &err) != FV_OK) fail_msg("%s", err.msg);
    fv_backend_mark(b, 1);
    if (fv_backend_wait(b, "the test", &err) != FV_OK) fail_msg("%s", err.msg);
    fv_bc_expect(b, &c1, "a frame through pinned memory", 1, 0, 4000, 4000, 0, 0, 1);
    for (int i = 0; i < FV_BC_N; i++) {
        const float want = i < 2 ? 0.0f : (i >= 100 && i < 600) ? INFINITY : (float)i;
        if (host[i] != want) fail_msg("%s: element %d is %g, not %g", fv_device_name(device), i, host[i], want);
    }
    if (!(fv_backend_elapsed_ms(b, 0, 1) >= 0.0)) fail_msg("marks: %g ms", fv_backend_elapsed_ms(b, 0, 1));

    /* a launch that does not fit its declaration is refused, not run */
    if (fv_backend_launch(b, &fv_fill_f32_kernel, 10, 2, &fa, NULL, &err) != FV_ERR_INTERNAL) fail_msg("a one-dimensional kernel ran on 10x2 items");

    /* a mirror copies when its bytes change, not otherwise, and never from pageable memory */
    fv_mirror m = {0};
    int table[64];
    for (int i = 0; i < 64; i++) table[i] = i * i;
    const void *dev = NULL;
    fv_backend_calls c2;
    fv_backend_calls_get(b, &c2);
    if (fv_mirror_fill(b, &m, table, sizeof table, &dev, "a test table", &err) != FV_OK ||
        fv_mirror_fill(b, &m, table, sizeof table, &dev, "a test table", &err) != FV_OK)
        fail_msg("%s", err.msg);
    fv_bc_expect(b, &c2, "a mirror filled twice with the same bytes", 0, 0, sizeof table, 0, 1, 0, 0);
    table[7] = -1;
    if (fv_mirror_fill(b, &m, table, sizeof table, &dev, "a test table", &err) != FV_OK) fail_msg("%s", err.msg);
    table[7] = 49; /* the copy was staged: the caller's array may change at once */
    fv_bc_expect(b, &c2, "a changed mirror", 0, 0, 2 * sizeof table, 0, 1, 0, 0);
    int back[64];
    fv_buffer pin2 = {0};
    if (fv_pinned_ensure(b, &pin2, sizeof back, "a test table", &err) != FV_OK ||
        fv_backend_download(b, pin2.p, dev, sizeof back, "a test table", &err) != FV_OK || fv_backend_wait(b, "the test", &err) != FV_OK)
        fail_msg("%s", err.msg);
    memcpy(back, pin2.p, sizeof back);
    for (int i = 0; i < 64; i++)
        if (back[i] != (i == 7 ? -1 : i * i)) fail_msg("the mirror holds %d at %d", back[i], i);

    /* a copy into pageable memory blocks on CUDA: counted as such */
    fv_backend_calls c3;
    fv_backend_calls_get(b, &c3);
    if (fv_backend_download(b, back, dev, sizeof back, "a test table", &err) != FV_OK) fail_msg("%s", err.msg);
    fv_bc_expect(b, &c3, "a copy into pageable memory", gpu ? 1 : 0, gpu ? 1 : 0, 0, sizeof back, 0, 0, 0);

    fv_mirror_release(b, &m);
    fv_pinned_release(b, &pin2);
    fv_pinned_release(b, &pin);
    fv_buffer_release(b, &buf);
    fv_backend_destroy(b);
}

#endif
