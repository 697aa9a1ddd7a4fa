# Outputs never clobber inputs, and outputs that cannot be written are refused before any work
# (issue 42, items 2 and 7). Each check below failed before the fix: the input was replaced with
# exit status 0, the mode of a replaced file became 0644, a read-only target was replaced, and a
# folder, FIFO or device given as --out was refused only after the frame had rendered (the
# `timeout` cases: a render that size takes minutes). Also a UTF-8 byte order mark before a gaze
# trace or an EyeLink recording, which broke their first line.
. "$(dirname "$0")/lib.sh"
D=$SRC/tests/data
R="$FOVEA render --size 8x8 --spp 1 --quiet"
BIG="timeout 30 $FOVEA render cornell --size 4000x4000 --spp 4096 --quiet"
cd "$TMP" || exit 1

# same(): the file is byte for byte what it was (its copy in keep/)
mkdir keep
same() { cmp -s "$1" "keep/$1" || fail "$1 was changed"; }

# ---- gaze import: the recording as --out, by name, symbolic link and hard link ----
cp "$D/pupil_gaze_positions.csv" rec.csv && cp rec.csv keep/
ln -s rec.csv link.csv
ln rec.csv hard.csv
for o in rec.csv ./rec.csv link.csv hard.csv; do
  expect 2 "--out $o is the recording rec.csv" -- $FOVEA gaze import rec.csv --out $o
done
same rec.csv

# ---- compare: a heat map over either image ----
$R cornell --out a.png && $R cornell --seed 2 --out b.png || fail "rendering the images"
cp a.png b.png keep/
ln -s b.png heat.png
expect 2 "--heatmap a.png is the reference image a.png" -- $FOVEA compare a.png b.png --heatmap a.png
expect 2 "--heatmap heat.png is the test image b.png" -- $FOVEA compare a.png b.png --heatmap heat.png
same a.png
same b.png

# ---- render: --stats-json and --out over the scene, the gaze trace, the camera trace ----
cp "$D/scene.json" sc.json && cp "$D/quad.ply" .
printf 'time,x,y\n0,0.5,0.5\n1,0.4,0.6\n' > tr.csv
cp "$D/camera.csv" cam.csv
cp sc.json tr.csv cam.csv keep/
expect 2 "--stats-json sc.json is the scene file sc.json" -- $R sc.json --stats-json sc.json --out o.png
expect 2 "--stats-json tr.csv is the gaze trace tr.csv" -- $R sc.json --gaze-trace tr.csv --stats-json tr.csv --out o.png
expect 2 "--stats-json cam.csv is the camera trace cam.csv" -- $R sc.json --camera-trace cam.csv --stats-json cam.csv --out o.png
ln -s sc.json scene.png
expect 2 "--out scene.png is the scene file sc.json" -- $R sc.json --out scene.png
# the second frame's file of a sequence, the right eye's of a pair
ln tr.csv seq_0001.png
expect 2 "--out seq_0001.png is the gaze trace tr.csv" -- $R sc.json --gaze-trace tr.csv --frames 2 --out seq.png
ln cam.csv st_right.png
expect 2 "--out st_right.png is the camera trace cam.csv" -- $R sc.json --camera-trace cam.csv --stereo 0.1 --out st.png
same sc.json
same tr.csv
same cam.csv
[ -e o.png ] && fail "o.png was written"

# ---- bench: --save-scenario over the scene; the report over the scenario ----
B="$FOVEA bench --quiet --methods pt --reference pt:spp=1 --size 8x8"
expect 2 "--save-scenario sc.json is the scene file sc.json" -- $B --scene sc.json --save-scenario sc.json --out bo
expect 2 "--save-scenario tr.csv is the gaze trace tr.csv" -- $B --scene sc.json --gaze-trace tr.csv --save-scenario tr.csv --out bo
same sc.json
same tr.csv
expect 0 "" -- $B --scene cornell --save-scenario gen.json --check
mkdir bo && cp gen.json bo/cornell-pt.json && cp bo/cornell-pt.json keep/scenario.json
expect 2 "--out bo: the report bo/cornell-pt.json is the scenario bo/cornell-pt.json" -- $FOVEA bench --quiet bo/cornell-pt.json --out bo
cmp -s bo/cornell-pt.json keep/scenario.json || fail "the scenario was replaced by its report"

# ---- a replaced file keeps its mode; a read-only one is refused, before any work ----
cp "$D/eyelink_mono.asc" mono.asc
touch private.csv && chmod 600 private.csv
expect 0 "" -- $FOVEA gaze import mono.asc --out private.csv --quiet
[ "$(stat -c %a private.csv)" = 600 ] || fail "a 0600 file became $(stat -c %a private.csv) when replaced"
touch ro.csv && chmod 444 ro.csv
expect 2 "cannot write 'ro.csv': the file is read-only (mode 0444)" -- $FOVEA gaze import mono.asc --out ro.csv
[ -s ro.csv ] && fail "the read-only file was replaced"
touch ro.png && chmod 444 ro.png
expect 2 "cannot write 'ro.png': the file is read-only (mode 0444)" -- $BIG --out ro.png

# ---- --out a folder, a FIFO or a device: refused before the frame renders ----
mkdir dir.png
mkfifo fifo.png
ln -s /dev/null null.png
expect 2 "cannot write 'dir.png': not a regular file (a directory)" -- $BIG --out dir.png
expect 2 "cannot write 'fifo.png': not a regular file (a FIFO)" -- $BIG --out fifo.png
expect 2 "cannot write 'null.png': not a regular file (a character device)" -- $BIG --out null.png
expect 2 "cannot write 'dir.png': not a regular file (a directory)" -- $BIG --out o.png --stats-json dir.png

# ---- a UTF-8 byte order mark before the first line is skipped ----
# an EyeLink file whose first line is a message (no "**" preamble), and a trace whose first line
# is a sample: the mark made both unreadable
{ printf '\357\273\277'; grep -v '^\*\*' "$D/eyelink_mono.asc"; } > bom.asc
expect 0 "" -- $FOVEA gaze import bom.asc --out bom_import.csv --quiet
grep -v '^#' bom_import.csv > plain_import.csv
$FOVEA gaze import mono.asc --out mono_import.csv --quiet
grep -v '^#' mono_import.csv | cmp -s - plain_import.csv || fail "the BOM'd recording imports differently"
{ printf '\357\273\277'; tail -n +2 tr.csv; } > bom_tr.csv
expect 0 "" -- $R cornell --gaze-trace bom_tr.csv --out bom.png

finish
