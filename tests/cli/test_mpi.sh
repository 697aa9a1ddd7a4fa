#!/usr/bin/env bash
# `mpirun -n N fovea render` (docs/distributed.md): a split still (pt's samples, ppm's passes) is
# the one-process image bit for bit (shared memory and TCP), a split sequence writes the one-process frames (fipr after its
# stated warm-up), pm's passes are not split and say so once, rank 0 alone draws one bar for the
# whole job, a failed job says one line and leaves no output, a killed rank ends the job. The
# bench's report, and the reference cache it splits over the ranks, equal a one-process run's.
# Skipped (exit 77) where fovea was built without MPI or mpirun is missing.
. "$(dirname "$0")/lib.sh"
fv_mpi_setup
# Images are compared byte for byte, so written without metadata (which holds render times).
# Ranks on whatever cores there are; -q keeps mpirun's own banners out of the messages checked.
MPI="${MPIENV[*]} mpirun -q --oversubscribe --bind-to none"
cd "$TMP" || exit 1
same() { cmp -s "$1" "$2" || fail "$3: $1 and $2 differ"; }

# A still of 200 spp: four sample blocks, split over 2 and 3 ranks, over shared memory and TCP.
R="render cornell --size 40x32 --spp 200 --threads 1 --quiet --no-metadata"
"$FOVEA" $R --out one.exr || fail "one-process still"
$MPI -n 2 "$FOVEA" $R --out two.exr || fail "2-rank still"
$MPI -n 3 "$FOVEA" $R --out three.exr || fail "3-rank still"
$MPI -n 2 --mca btl tcp,self "$FOVEA" $R --out tcp.exr || fail "2-rank still over TCP"
same one.exr two.exr "2 ranks (colour and every auxiliary layer)"
same one.exr three.exr "3 ranks"
$MPI -n 5 "$FOVEA" $R --out five.exr || fail "5-rank still (more ranks than blocks)"
same one.exr five.exr "5 ranks for 4 blocks"
same one.exr tcp.exr "2 ranks over TCP"
# A stereo still: both eyes split by the same blocks, each eye the one-process eye.
"$FOVEA" $R --stereo 0.1 --out st1.exr && $MPI -n 2 "$FOVEA" $R --stereo 0.1 --out st2.exr || fail "stereo still"
same st1_left.exr st2_left.exr "a stereo still's left eye over 2 ranks"
same st1_right.exr st2_right.exr "a stereo still's right eye over 2 ranks"
# The split is real: rank 1 alone would give another image (its blocks only).
"$FOVEA" $R --param block_first=2 --param block_count=2 --out half.exr || fail "half the blocks"
cmp -s one.exr half.exr && fail "two of four blocks gave the whole image"
# One block (64 spp or fewer) is not split: rank 0 renders it, the same image.
"$FOVEA" render cornell --size 40x32 --spp 8 --quiet --no-metadata --out small1.pfm
$MPI -n 2 "$FOVEA" render cornell --size 40x32 --spp 8 --quiet --no-metadata --out small2.pfm
same small1.pfm small2.pfm "a one-block still"

# A ppm reference of 150 passes (three blocks of passes) over 2 ranks: the one-process image.
P="render cornell --method ppm --param passes=150 --param photons=2000 --size 32x24 --threads 1 --quiet --no-metadata"
"$FOVEA" $P --out ppm1.exr || fail "one-process ppm"
$MPI -n 2 "$FOVEA" $P --out ppm2.exr || fail "2-rank ppm"
same ppm1.exr ppm2.exr "ppm over 2 ranks"
"$FOVEA" $P --param block_first=1 --out ppmpart.exr || fail "ppm's last two blocks"
cmp -s ppm1.exr ppmpart.exr && fail "two of three blocks of passes gave the whole ppm image"
# pm's passes (a filtered running mean) are not split: rank 0 renders them, the one-process image,
# and says so once.
M="render cornell --method pm --param passes=3 --param photons=2000 --size 24x24 --threads 1 --no-metadata"
"$FOVEA" $M --quiet --out pm1.pfm || fail "one-process pm passes=3"
$MPI -n 2 "$FOVEA" $M --out pm2.pfm 2>pm2.err || fail "2-rank pm passes=3: $(cat pm2.err)"
same pm1.pfm pm2.pfm "pm passes=3 over 2 ranks"
n=$(grep -c "mpi: the still is not split over 2 ranks (pm's 3 passes are averaged and filtered in one process" pm2.err)
[ "$n" = 1 ] || fail "pm's passes: expected the note once, got $n: $(cat pm2.err)"

# A sequence of a method without temporal state along a camera trace: every frame as one process.
S="render cornell --size 32x24 --spp 4 --frames 5 --threads 1 --quiet --no-metadata --camera-trace $SRC/tests/data/camera.csv --fps 2"
"$FOVEA" $S --out s.pfm || fail "one-process sequence"
$MPI -n 2 "$FOVEA" $S --out d.pfm || fail "2-rank sequence"
for f in 0000 0001 0002 0003 0004; do same "s_$f.pfm" "d_$f.pfm" "sequence frame $f"; done
[ "$(ls d_*.pfm | wc -l)" = 5 ] || fail "the 2-rank sequence wrote $(ls d_*.pfm | wc -l) frames, expected 5"
grep -q '"warmup_frames":[[:space:]]*0' d_ranks.json || fail "the manifest lacks warmup_frames 0: $(cat d_ranks.json)"
# One bar for the whole job, drawn by rank 0 alone (launchers give a rank's stdout a terminal, so
# rank 0 draws it): 2 frames over 3 ranks leave rank 0 no frame, yet its bar follows ranks 1 and 2
# to 100%, once, never going back (a second drawing rank would restart at its own few percent).
$MPI -n 3 "$FOVEA" render cornell --size 32x32 --spp 64 --frames 2 --threads 1 --no-metadata --out pb.pfm >pb.out 2>pb.err ||
  fail "3-rank sequence of 2 frames: $(cat pb.err)"
python3 - pb.err <<'EOS' || fail "the job's bar: $(tr '\r' '\n' <pb.err | grep -o '[0-9]*%' | tr '\n' ' ')"
import re, sys
p = [int(x) for x in re.findall(r"\]\s*(\d+)%", open(sys.argv[1], errors="replace").read())]
assert p, "no bar"
assert all(a <= b for a, b in zip(p, p[1:])), "went back"
assert p[-1] == 100 and p.count(100) == 1, "did not end at 100% once"
EOS
# fipr with refresh=4 keeps pixels for up to 3 frames: after its 3 warm-up frames rank 1's block is
# the one-process sequence bit for bit; without them its first frame is not.
printf 'time,x,y\n0,0.2,0.3\n0.3,0.8,0.6\n' >gaze.csv
F="render sdf-columns --method fipr --param refresh=4 --size 48x32 --frames 8 --threads 1 --quiet --gaze-trace gaze.csv"
"$FOVEA" $F --out f.pfm || fail "one-process fipr"
$MPI -n 2 "$FOVEA" $F --out g.pfm || fail "2-rank fipr"
for f in 0 1 2 3 4 5 6 7; do same "f_000$f.pfm" "g_000$f.pfm" "fipr frame $f"; done
grep -q '"rendered_from":[[:space:]]*1' g_ranks.json || fail "the manifest does not say rank 1 started at frame 1: $(cat g_ranks.json)"
$MPI -n 2 "$FOVEA" $F --warmup 0 --out h.pfm || fail "2-rank fipr without warm-up"
cmp -s f_0004.pfm h_0004.pfm && fail "fipr's frame 4 needs no warm-up: the test shows nothing"

# Bad input every rank sees: one line, as one process says it, and no file.
expect 2 "image size 0x4" -- $MPI -n 2 "$FOVEA" render --size 0x4 --out bad.png
expect 2 "unknown method 'nope'" -- $MPI -n 2 "$FOVEA" render --method nope --out bad.png
# Bad input one rank sees: one line naming the rank.
cat >onebad.sh <<EOS
if [ "\$OMPI_COMM_WORLD_RANK" = 1 ]; then s=missing.json; else s=cornell; fi
exec "$FOVEA" render "\$s" --size 32x32 --spp 200 --quiet --out bad.png
EOS
expect 2 "rank 1: fovea render: cannot open scene 'missing.json'" -- $MPI -n 2 bash onebad.sh
ls bad.* .bad* >/dev/null 2>&1 && fail "a failed job left output: $(ls -a | grep bad)"
# A frame of rank 1's share whose name is a folder: every output is checked before any work (issue
# 42), so the job is refused at once with one line, and no rank renders a frame.
mkdir w_0010.pfm
expect 2 "fovea render: cannot write 'w_0010.pfm': not a regular file" -- \
  $MPI -n 2 "$FOVEA" render cornell --size 32x32 --spp 256 --frames 20 --threads 1 --quiet --out w.pfm
n=$(ls w_*.pfm 2>/dev/null | grep -vc w_0010)
[ "$n" -eq 0 ] || fail "$n frames were written although an output was refused"
[ -e w_ranks.json ] && fail "a refused sequence wrote its manifest"

# The bench split over ranks (rows dealt round-robin, rank 0 gathers them): one report, equal to a
# one-process run's except the timings (and the command, date and rank fields that say so); the
# images' pixels equal; the table printed once.
B="bench pt-cornell --quick --threads 1"
"$FOVEA" $B --out bone >/dev/null 2>&1 || fail "one-process bench"
$MPI -n 2 "$FOVEA" $B --out btwo >btwo.out 2>btwo.err || fail "2-rank bench: $(cat btwo.err)"
python3 - bone/pt-cornell.json btwo/pt-cornell.json <<'EOS' || fail "the 2-rank bench report differs from one process's beyond timings"
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
timing = {"ms_per_frame", "frame_ms", "stages_ms", "stages_ms_range", "stages_serial_share", "speedup", "date", "command", "ranks", "timed_on_rank"}
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in timing}
    return [strip(v) for v in x] if isinstance(x, list) else x
a["reference"].pop("ms_per_frame", None), b["reference"].pop("ms_per_frame", None)
assert b["ranks"] == 2 and sorted(r["timed_on_rank"] for r in b["results"]) == [0, 0, 1], b["results"]
sys.exit(0 if strip(a) == strip(b) else 1)
EOS
for f in bone/pt-cornell/pt-spp=*[0-9].png; do
  mse=$("$FOVEA" compare "$f" "btwo/pt-cornell/$(basename "$f")" --json | python3 -c 'import json, sys; print(json.load(sys.stdin)["regions"]["all"]["mse"])')
  [ "$mse" = 0 ] || fail "$(basename "$f"): the 2-rank image differs (MSE $mse)"
done
n=$(grep -c '^| pt-spp=4 ' btwo.out)
[ "$n" = 1 ] || fail "the 2-rank bench printed its table $n times"
# Its reference (pt, 256 spp: four sample blocks) was split over the ranks as `render` splits a
# still, and cached bit for bit as one process caches it; so was its noise probe (64 spp, one
# block: rank 0's).
grep -q "reference: rendering 1 frame(s) with pt (0 cached), split over the ranks" btwo.err || fail "the 2-rank reference was not split: $(cat btwo.err)"
[ "$(ls bone/cache | wc -l)" = 2 ] || fail "expected a reference and a probe in the cache: $(ls bone/cache)"
for f in bone/cache/*; do same "$f" "btwo/cache/$(basename "$f")" "the 2-rank bench's cached $(basename "$f")"; done
# A reference of 3 frames without state between them (8 spp: one block a frame) over 3 ranks, one
# frame each: the cache of one process; again with one frame missing from the cache (rank 0 alone).
C="bench --scene cornell --methods pt:spp=1,pt:spp=2 --reference pt:spp=8 --frames 3 --size 24x16 --threads 1 --quiet"
"$FOVEA" $C --out cone >/dev/null 2>&1 || fail "one-process bench of 3 frames"
$MPI -n 3 "$FOVEA" $C --out cthree >/dev/null 2>cthree.err || fail "3-rank bench of 3 frames: $(cat cthree.err)"
[ "$(ls cone/cache | grep -c '^ref-')" = 3 ] || fail "expected 3 reference frames in the cache: $(ls cone/cache)"
for f in cone/cache/*; do same "$f" "cthree/cache/$(basename "$f")" "the 3-rank bench's cached $(basename "$f")"; done
rm "cthree/cache/$(ls cthree/cache | grep '^ref-' | head -1)"
$MPI -n 3 "$FOVEA" $C --out cthree >/dev/null 2>cthree.err || fail "3-rank bench with 2 cached frames: $(cat cthree.err)"
for f in cone/cache/*; do same "$f" "cthree/cache/$(basename "$f")" "the 3-rank bench's re-rendered $(basename "$f")"; done
# Bad input every rank sees: one line, no folder.
expect 2 "unknown scenario 'no-such'" -- $MPI -n 2 "$FOVEA" bench no-such --quick --out bbad
expect 2 "spp=0: out of range" -- $MPI -n 2 "$FOVEA" bench --scene cornell --methods pt:spp=0 --out bbad
[ -e bbad ] && fail "a refused bench left $(ls bbad)"
# A failure on rank 0 while it writes a row rank 1 timed: one line, and no report.
mkdir -p bfail/cornell-pt-pt-2/pt-2.png
expect 2 "pt-2.png" -- $MPI -n 2 "$FOVEA" bench --scene cornell --methods pt:spp=1,pt:spp=2 --reference pt:spp=4 --size 16x16 --quiet --out bfail
ls bfail/*.json >/dev/null 2>&1 && fail "a failed split bench wrote its report"

# A rank killed mid-render: the job ends within seconds, nonzero, with no image and no temporary.
cat >killme.sh <<EOS
echo \$\$ >"pid.\$OMPI_COMM_WORLD_RANK"
exec "$FOVEA" render cornell --size 128x128 --spp 1000000 --threads 1 --quiet --out killed.png
EOS
rm -f pid.*
t0=$(date +%s)
# (without -q: mpirun's own line names the rank that died and its signal)
"${MPIENV[@]}" mpirun --oversubscribe --bind-to none -n 2 bash killme.sh >kill.out 2>&1 &
job=$!
for _ in $(seq 50); do [ -s pid.1 ] && [ -s pid.0 ] && break; sleep 0.1; done
sleep 1
kill -9 "$(cat pid.1)" 2>/dev/null || fail "no rank 1 to kill"
wait "$job"
rc=$?
t1=$(date +%s)
[ "$rc" != 0 ] || fail "the job with a killed rank exited 0"
[ $((t1 - t0)) -le 20 ] || fail "the job with a killed rank took $((t1 - t0)) s to end"
grep -q "rank 1" kill.out || fail "mpirun did not name the killed rank: $(cat kill.out)"
ls -a | grep -q killed && fail "a killed job left output: $(ls -a | grep killed)"
sleep 0.5
st=$(ps -o stat= -p "$(cat pid.0)" 2>/dev/null)
case "$st" in "" | Z*) ;; *) fail "rank 0 outlived the job (state $st)" ;; esac
finish
