# scripts/gpu-resources (docs/gpu.md, "What ptxas reports") on a small made-up build: a source tree
# with three kernels and their launches, and the ptxas record cmake/ptxas-record would keep beside
# the object. Runs on every build, CUDA or not: the table's block sizes, occupancy, --write and
# --check (stale: 1 with the diff; another nvcc: 77), and the refusals the real test relies on.
. "$(dirname "$0")/lib.sh"
GR=$SRC/scripts/gpu-resources
S=$TMP/src
B=$TMP/build
OBJ=$B/CMakeFiles/fovea_obj.dir/src/device/cuda
mkdir -p "$S/src/device/cuda" "$S/docs" "$OBJ"
printf 'CMAKE_HOME_DIRECTORY:INTERNAL=%s\n' "$S" >"$B/CMakeCache.txt"

cat >"$S/src/device/cuda/k.h" <<'EOF'
#define K_THREADS 256
EOF
cat >"$S/src/device/cuda/k.cu" <<'EOF'
#include "k.h"
#define K_BLOCK 8
__global__ void fv_k_tile(float *p) {}
__global__ void fv_k_wide(float *p) {}
__global__ void fv_k_rows(float *p) {}
static void go(float *p, cudaStream_t st)
{
    /* FV_CUDA_LAUNCH(fv_k_tile, 1, 999, st) in a comment is no launch */
    const dim3 grid(4, 4), block(K_BLOCK, K_BLOCK);
    FV_CUDA_LAUNCH(&tally, fv_k_tile, grid, block, st)(p);
    FV_CUDA_LAUNCH(&tally, fv_k_wide, grid, dim3(K_BLOCK, K_BLOCK), st)(p);
    FV_CUDA_LAUNCH(&tally, fv_k_rows, 16, K_THREADS / 2, st)(p);
}
EOF
# record ARCH REGS: one architecture's report of the three kernels, as ptxas prints it.
record() {
  cat <<EOF
ptxas info    : 0 bytes gmem
ptxas info    : Compiling entry function '_Z9fv_k_rowsPf' for 'sm_$1'
ptxas info    : Function properties for _Z9fv_k_rowsPf
    0 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads
ptxas info    : Used 32 registers, used 0 barriers, 360 bytes cmem[0]
ptxas info    : Compiling entry function '_Z9fv_k_widePf' for 'sm_$1'
ptxas info    : Function properties for _Z9fv_k_widePf
    3344 bytes stack frame, 8 bytes spill stores, 12 bytes spill loads
ptxas info    : Used 181 registers, used 1 barriers, 3344 bytes cumulative stack size, 24 bytes smem, 360 bytes cmem[0]
ptxas info    : Compiling entry function '_Z9fv_k_tilePf' for 'sm_$1'
ptxas info    : Function properties for _Z9fv_k_tilePf
    3080 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads
ptxas info    : Used $2 registers, used 0 barriers, 3080 bytes cumulative stack size, 360 bytes cmem[0]
ptxas info    : Compile time = 1.5 ms
ptxas info    : Function properties for _ZN34_INTERNAL_0123abcd_4_k_cu_89abcdef7fv_helpEf
    0 bytes stack frame, 0 bytes spill stores, 0 bytes spill loads
EOF
}
: >"$OBJ/k.cu.o"
sleep 0.01
{ echo "# nvcc 13.0.88"; record 80 164; record 90 165; } >"$OBJ/k.cu.o.ptxas"

# The table: source order, both architectures, threads from the launches, occupancy at 64 warp slots
# (165 registers: 3 warps per sub-partition, 12 per SM; 181: 2 and 8; 32 registers at 128 threads:
# every slot).
python3 "$GR" "$B" >"$TMP/table" 2>"$TMP/err" || fail "the table: $(cat "$TMP/err")"
want='| fv_k_tile | sm_80 | 164 | 3080 | 0 | 0 | 0 | 64 | 12 | 19% | regs | ? |
| fv_k_tile | sm_90 | 165 | 3080 | 0 | 0 | 0 | 64 | 12 | 19% | regs | ? |
| fv_k_wide | sm_80 | 181 | 3344 | 8 | 12 | 24 | 64 | 8 | 13% | regs | ? |
| fv_k_wide | sm_90 | 181 | 3344 | 8 | 12 | 24 | 64 | 8 | 13% | regs | ? |
| fv_k_rows | sm_80 | 32 | 0 | 0 | 0 | 0 | 128 | 64 | 100% | regs, warps | ? |
| fv_k_rows | sm_90 | 32 | 0 | 0 | 0 | 0 | 128 | 64 | 100% | regs, warps | ? |'
got=$(grep '^| fv_k_' "$TMP/table")
[ "$got" = "$want" ] || fail "kernel rows differ: $got"
grep -qF '| fv_help | k.cu | sm_90 | 0 | 0 | 0 | ? | ? |' "$TMP/table" || fail "no row for the helper: $(cat "$TMP/table")"
grep -qF 'nvcc 13.0.88, sm_80 and sm_90' "$TMP/table" || fail "the header names no compiler"

# --write puts it in the build's source tree; --check then passes, and fails on any difference.
expect 0 "" -- python3 "$GR" --write "$B"
cmp -s "$TMP/table" "$S/docs/gpu-resources.md" || fail "--write wrote other than the table"
expect 0 "" -- python3 "$GR" --check "$S/docs/gpu-resources.md" "$B"
sed 's/| fv_k_wide | sm_90 | 181 |/| fv_k_wide | sm_90 | 180 |/' "$S/docs/gpu-resources.md" >"$TMP/stale.md"
python3 "$GR" --check "$TMP/stale.md" "$B" >"$TMP/out" 2>&1
[ $? = 1 ] || fail "a stale table passed --check"
grep -qF -- '-| fv_k_wide | sm_90 | 180 |' "$TMP/out" && grep -qF 'scripts/gpu-resources --write' "$TMP/out" ||
  fail "the stale table's diff or the command to regenerate is missing: $(cat "$TMP/out")"
# Another nvcc: skipped; a table of sm_90 only: compared on sm_90.
sed 's/nvcc 13.0.88/nvcc 12.9.1/' "$S/docs/gpu-resources.md" >"$TMP/other.md"
python3 "$GR" --check "$TMP/other.md" "$B" >"$TMP/out" 2>&1
[ $? = 77 ] || fail "another nvcc's table was not skipped: $(cat "$TMP/out")"
grep -v '| sm_80 |' "$S/docs/gpu-resources.md" >"$TMP/sm90.md"
expect 0 "" -- python3 "$GR" --check "$TMP/sm90.md" "$B"

# Refusals: a kernel no launch names, a block size it cannot evaluate, an object without its record.
cp "$S/src/device/cuda/k.cu" "$TMP/k.cu"
sed -i '/fv_k_rows, 16/d' "$S/src/device/cuda/k.cu"
expect 1 "no launch names the kernel(s) fv_k_rows" -- python3 "$GR" "$B"
sed 's/K_THREADS \/ 2/n_threads(p)/' "$TMP/k.cu" >"$S/src/device/cuda/k.cu"
expect 1 "k.cu:12: cannot evaluate the block size 'n_threads(p)'" -- python3 "$GR" "$B"
cp "$TMP/k.cu" "$S/src/device/cuda/k.cu"
touch -d '+1 second' "$OBJ/k.cu.o"
expect 1 "has no ptxas record of its own compile" -- python3 "$GR" "$B"
finish
