# `--device`: each refusal exits 2 with one line naming why and leaves no file; the portable
# backend renders pt to an image like the CPU's (docs/gpu.md).
. "$(dirname "$0")/lib.sh"
OUT=$TMP/out.png
R="$FOVEA render"

expect 2 "device 'gpu' is not one of cpu, portable, cuda, auto" -- $R cornell --device gpu --size 8x8 --out "$OUT"
expect 2 "device '' is not one of" -- $R cornell --device "" --size 8x8 --out "$OUT"
# A method without a CUDA version names the methods that have one.
expect 2 "method 'fpm' does not run on device cuda (methods that do: pt, vpolar, cartesian, cartesian-full, linear-falloff, log-polar, sdf-gt, sdf-relaxed, ipr, fipr)" -- $R cornell --method fpm --device cuda --size 8x8 --out "$OUT"
expect 2 "method 'fpm' does not run on device portable (methods that do: pt, vpolar, cartesian, cartesian-full, linear-falloff, log-polar, sdf-gt, sdf-relaxed, ipr, fipr)" -- $R cornell --method fpm --device portable --size 8x8 --out "$OUT"
# The same refusals through --param.
expect 2 "parameter device=nope: expected one of cpu, portable, cuda, auto" -- $R cornell --method pt --param device=nope --size 8x8 --out "$OUT"
# pt on CUDA: this build has no CUDA, or this machine no GPU (CI has neither); either is one line.
if "$FOVEA" render cornell --device cuda --spp 1 --size 8x8 --out "$TMP/cuda.png" 2>"$TMP/cuda.err"; then
  [ -s "$TMP/cuda.png" ] || fail "--device cuda succeeded without writing its image"
else
  code=$?
  [ "$code" = 2 ] || fail "--device cuda exited $code, expected 2 or 0"
  [ "$(grep -c '' "$TMP/cuda.err")" = 1 ] || fail "--device cuda printed more than one line: $(cat "$TMP/cuda.err")"
  grep -qE "built without CUDA|no CUDA device" "$TMP/cuda.err" || fail "--device cuda refusal names neither cause: $(cat "$TMP/cuda.err")"
  [ ! -e "$TMP/cuda.png" ] || fail "--device cuda refused but left $TMP/cuda.png"
fi
[ ! -e "$OUT" ] || fail "a refused render left $OUT"

# auto falls back to the CPU where CUDA cannot run, and for a method without CUDA.
expect 0 "" -- $R cornell --method vpolar --device auto --size 16x16 --out "$TMP/auto-vp.png"
expect 0 "" -- $R cornell --device auto --spp 1 --size 16x16 --out "$TMP/auto.png"
# The portable backend renders pt and every auxiliary channel (unit tests compare it with the CPU's).
expect 0 "" -- $R cornell --device portable --spp 2 --size 24x24 --out "$TMP/portable.exr"
[ -s "$TMP/portable.exr" ] || fail "--device portable wrote no image"
expect 0 "" -- $R cornell --device portable --spp 2 --size 24x24 --frames 2 --stereo 0.1 --out "$TMP/portable-st.png"

# The Visual-Polar family on the portable backend, over a sequence (its denoiser's history carried
# from frame to frame; test_device_vpolar compares the images with the CPU's), show=space included
# (the pipeline's sample-space image is on the host either way).
for m in vpolar cartesian cartesian-full linear-falloff log-polar; do
  expect 0 "" -- $R cornell --method $m --device portable --size 32x24 --frames 2 --warmup 1 --out "$TMP/$m-portable.png"
  [ -s "$TMP/$m-portable_0001.png" ] || fail "$m --device portable wrote no second frame"
done
expect 0 "" -- $R cornell --method vpolar --device portable --param show=space --size 32x24 --out "$TMP/vp-space.png"

# The sphere tracers on the portable backend (test_device_sdf compares them with the CPU's bit for
# bit; fipr over three frames, so its kept history is read), and on CUDA the same one line as pt
# where it cannot run.
for m in sdf-gt sdf-relaxed ipr fipr; do
  expect 0 "" -- $R sdf-primitives --method $m --device portable --param spp=4 --size 24x16 --frames 3 --out "$TMP/$m-portable.pfm" --no-metadata
  expect 0 "" -- $R sdf-primitives --method $m --device cpu --param spp=4 --size 24x16 --frames 3 --out "$TMP/$m-cpu.pfm" --no-metadata
  for i in 0000 0001 0002; do
    cmp -s "$TMP/$m-portable_$i.pfm" "$TMP/$m-cpu_$i.pfm" || fail "$m: --device portable and --device cpu wrote different images (frame $i)"
  done
  if "$FOVEA" render sdf-primitives --method $m --device cuda --size 8x8 --out "$TMP/$m-cuda.png" 2>"$TMP/$m-cuda.err"; then
    [ -s "$TMP/$m-cuda.png" ] || fail "$m --device cuda succeeded without writing its image"
  else
    code=$?
    [ "$code" = 2 ] || fail "$m --device cuda exited $code, expected 2 or 0"
    [ "$(grep -c '' "$TMP/$m-cuda.err")" = 1 ] || fail "$m --device cuda printed more than one line: $(cat "$TMP/$m-cuda.err")"
    grep -qE "built without CUDA|no CUDA device" "$TMP/$m-cuda.err" || fail "$m --device cuda refusal names neither cause"
    [ ! -e "$TMP/$m-cuda.png" ] || fail "$m --device cuda refused but left its image"
  fi
done
expect 2 "parameter show=steps: only the cpu device draws diagnostics (device portable renders the image)" -- $R sdf-primitives --method sdf-gt --device portable --param show=steps --size 8x8 --out "$TMP/steps.png"
expect 2 "parameter show=mask: only the cpu device draws diagnostics (device portable renders the image)" -- $R sdf-primitives --method fipr --device portable --param show=mask --size 8x8 --out "$TMP/mask.png"
[ ! -e "$TMP/steps.png" ] && [ ! -e "$TMP/mask.png" ] || fail "a refused sdf render left an image"

# bench --device: the measured methods that have the device run there, and the report says so.
expect 2 "--device: device 'gpu' is not one of" -- $FOVEA bench pt-cornell --quick --device gpu --out "$TMP/bench-bad" --quiet
[ ! -e "$TMP/bench-bad" ] || fail "a refused bench wrote $TMP/bench-bad"
expect 0 "" -- $FOVEA bench pt-cornell --quick --device portable --out "$TMP/bench" --quiet
n=$(grep -cE '"device":[[:space:]]*"portable"' "$TMP/bench/pt-cornell.json")
[ "$n" -ge 3 ] || fail "bench --device portable: $n methods report device portable, expected the sweep's 3"
grep -q "M rays/s" "$TMP/bench/pt-cornell.md" || fail "bench report lacks the ray throughput table"
finish
