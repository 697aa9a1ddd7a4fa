# Parallel regions per frame (docs/threads.md): every region wakes the team, so a frame's pacing
# depends on how many it opens. For every method on one of its scenes this checks that
#  - the "parallel_regions" counter --stats reports is exact: the regions of frames 2..3 equal what
#    the OpenMP runtime itself saw open between a 1-frame and a 3-frame run (tests/support/
#    omp_count.c, preloaded in front of libgomp, counts every GOMP_parallel call);
#  - a frame opens no more regions than the bound below (counted, not timed), measured after the
#    stages were merged into fewer regions (docs/threads.md has the before/after table).
# Run as `bash test_regions.sh FOVEA SRCDIR BUILDDIR`.
. "$(dirname "$0")/lib.sh"
BUILD=${3:-$(dirname "$FOVEA")}
SO="$BUILD/fv_omp_count.so"
[ -f "$SO" ] || { fail "no $SO (tests/CMakeLists.txt builds it)"; finish; }
# ASan must come first among the libraries; a preloaded module in front of it is fine here.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0"

bound() { # the most regions any of the three frames opened after the merges (before: docs/threads.md)
  case $1 in
    pt | sdf-gt | sdf-relaxed) echo 1 ;;     # one tile loop
    ipr | ir) echo 3 ;;
    fipr) echo 4 ;;                          # its mask is parallel now: one region more
    pm) echo 5 ;;                            # 11 before (A-Trous and its demodulation: 7 -> 1)
    pm-t) echo 8 ;;                          # the first frame also traces the static photons
    cartesian-full) echo 4 ;;
    cartesian | log-polar) echo 5 ;;
    vpolar | linear-falloff) echo 6 ;;       # 34 before (SVGF: about 28 -> 1)
    fir) echo 5 ;;                           # 10 before (its management: 6 regions -> 1)
    fpm-guided) echo 9 ;;                    # 13 before (its main pass and filters: 5 regions -> 1); 6 once warm
    fpm) echo 15 ;;                          # 21 before
    ir-low) echo 2 ;;                        # 18 before (a region per batch of maps and per shading pass -> 1)
    ppm) echo 256 ;;                         # a reference: 4 per pass, 64 passes
    *) echo 0 ;;                             # a new method: give it a bound
  esac
}
scene() { case $1 in pm | pm-t | fpm | fpm-guided | ppm) echo cornell-fpm ;; sdf-* | ipr | fipr) echo sdf-temple ;;
          ir | ir-low | fir) echo cornell-fir ;; *) echo cornell ;; esac; }
params() { case $1 in pm | pm-t | fpm | fpm-guided | ppm) echo "--param photons=3000" ;; pt) echo "--param spp=1" ;;
          ir-low) echo "--param vpls=600" ;; esac; } # ir-low: 3 batches of 266 maps

for m in $("$FOVEA" methods | awk '/^[a-z]/ {print $1}'); do
  for n in 1 3; do
    FV_OMP_COUNT_FILE="$TMP/count$n" LD_PRELOAD="$SO" "$FOVEA" render "$(scene "$m")" --method "$m" $(params "$m") \
      --size 32x24 --frames $n --threads 2 --stats --out "$TMP/r.pfm" 2>"$TMP/err$n" >/dev/null ||
      fail "$m: render exited $?: $(tail -n 2 "$TMP/err$n")"
  done
  # the counter of each frame, in order
  grep -o 'parallel_regions=[0-9]*' "$TMP/err3" | cut -d= -f2 >"$TMP/per"
  [ "$(grep -c '' "$TMP/per")" = 3 ] || { fail "$m: --stats printed no parallel_regions for 3 frames"; continue; }
  stats=$(sed -n '2,3p' "$TMP/per" | paste -sd+ | bc)
  runtime=$(( $(cat "$TMP/count3") - $(cat "$TMP/count1") ))
  [ "$stats" = "$runtime" ] || fail "$m: --stats counts $stats regions in frames 2-3, the runtime saw $runtime"
  b=$(bound "$m")
  while read -r r; do
    [ "$r" -le "$b" ] || fail "$m: $r parallel regions in a frame, bound $b"
  done <"$TMP/per"
  echo "$m: $(paste -sd' ' "$TMP/per") regions per frame (bound $b)"
done
# The merged regions give the same bits whatever the thread count (a barrier or a `single` too few
# would show here as a race): the methods whose stages were restructured, 1 against 3 threads.
for m in pm fpm vpolar cartesian fipr fir fpm-guided ir-low; do
  for t in 1 3; do
    "$FOVEA" render "$(scene "$m")" --method "$m" $(params "$m") --size 41x29 --frames 2 --gaze 0.3,0.6 --threads $t \
      --quiet --out "$TMP/t$t.pfm" || fail "$m --threads $t: exited $?"
  done
  for f in 0000 0001; do
    cmp -s "$TMP/t1_$f.pfm" "$TMP/t3_$f.pfm" || fail "$m: frame $f differs between 1 and 3 threads"
  done
done
finish
