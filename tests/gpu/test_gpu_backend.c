/* GPU tests (ctest label `gpu`): the device backend's contract on CUDA (tests/unit/backend_checks.h:
 * growing buffers, pinned copies that do not wait, mirrors copied only when changed, a declared
 * kernel's launch, one wait, the counts of every call). Built a second time against the CUDA
 * simulator (sim_test_gpu_backend), whose own count of host waits must agree. Exits 77 (skipped)
 * where CUDA cannot run. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <cmocka.h>
#include "fovea/fovea.h"
#include "../unit/backend_checks.h"
#include "../unit/testkit.h"
#include "sim_checks.h"

static void test_cuda(void **st)
{
    (void)st;
#ifdef FOVEA_CUDA_SIM
    const fv_sim_mark m = fv_sim_now();
#endif
    fv_backend_checks(FV_DEVICE_CUDA);
#ifdef FOVEA_CUDA_SIM
    /* the checks' two waits and the pageable copy's, nothing else */
    const fv_sim_mark now = fv_sim_now();
    if (now.host_waits - m.host_waits != 3)
        fail_msg("the simulator counted %llu host waits, the backend 3", (unsigned long long)(now.host_waits - m.host_waits));
#endif
    fv_sim_expect_freed("the backend checks");
}

int main(void)
{
    char why[256];
    if (!fv_device_available(FV_DEVICE_CUDA, why, sizeof why)) {
        printf("skipped: %s\n", why);
        return FV_GPU_TEST_NO_DEVICE;
    }
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_cuda)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
