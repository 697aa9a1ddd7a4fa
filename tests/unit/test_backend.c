/* The device backend's contract on the portable backend (tests/unit/backend_checks.h); CUDA's is
 * tests/gpu/test_gpu_backend.c. Also: a build without a CUDA backend refuses cuda with one line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>
#include "backend_checks.h"

static void test_portable(void **st)
{
    (void)st;
    fv_backend_checks(FV_DEVICE_PORTABLE);
}

static void test_refusals(void **st)
{
    (void)st;
    fv_backend *b = NULL;
    fv_error err;
    if (fv_backend_create(FV_DEVICE_CPU, &b, &err) != FV_ERR_INVALID || b) fail_msg("the cpu device made a kernel backend");
    if (!strstr(err.msg, "cpu")) fail_msg("the refusal does not name the device: %s", err.msg);
    char why[256];
    if (!fv_backend_cuda_probe(why, sizeof why)) {
        if (fv_backend_create(FV_DEVICE_CUDA, &b, &err) != FV_ERR_INVALID || b) fail_msg("cuda made a backend where the probe says: %s", why);
        if (strcmp(err.msg, why) != 0) fail_msg("the refusal '%s' is not the probe's '%s'", err.msg, why);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_portable), cmocka_unit_test(test_refusals)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
