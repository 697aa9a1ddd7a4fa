# `fovea gaze import` on the recordings of issue 25 (items 4 and 5), hand-made in tests/data:
# Pupil exports with a leading blank line, the old `timestamp` header and one row per eye
# (--eye), EyeLink at 2000 Hz in whole milliseconds, gzip-compressed, and with a break between
# trials. tests/unit/test_gaze_import.c checks the values; this checks the tool's side.
. "$(dirname "$0")/lib.sh"
D=$SRC/tests/data
G="$FOVEA gaze import"
R="$FOVEA render cornell --size 8x8 --spp 1 --quiet"

# ---- Pupil ----
expect 0 "" -- $G "$D/pupil_blank_first.csv" --out "$TMP/blank.csv"
grep -q "20 samples (1 missing), right eye" "$TMP/err" || fail "blank-first summary: $(cat "$TMP/err")"
expect 0 "" -- $G "$D/pupil_old_header.csv" --out "$TMP/old.csv"
grep -q '^0.19,0.390000,0.750000$' "$TMP/old.csv" || fail "old header: $(tail -n 2 "$TMP/old.csv")"
expect 2 "pupil_old_header.csv: no row is from the left eye" -- $G "$D/pupil_old_header.csv" --eye left --out "$TMP/x.csv"
# one row per eye: by default one gaze, the mean of the pair (moment 0: x 0.255 and 0.345)
expect 0 "" -- $G "$D/pupil_binocular.csv" --out "$TMP/both.csv"
grep -q "42 samples (1 missing), one gaze for both eyes (40 pairs of rows, one of each eye)" "$TMP/err" || fail "binocular summary: $(cat "$TMP/err")"
grep -q '^0,0.300000,0.400000$' "$TMP/both.csv" || fail "both.csv: $(head -n 3 "$TMP/both.csv")"
expect 0 "" -- $G "$D/pupil_binocular.csv" --eye left --out "$TMP/left.csv"
grep -q "42 samples (2 missing), left eye" "$TMP/err" || fail "left summary: $(cat "$TMP/err")"
grep -q '^0,0.345000,0.410000$' "$TMP/left.csv" || fail "left.csv: $(head -n 3 "$TMP/left.csv")"
expect 0 "" -- $G "$D/pupil_binocular.csv" --eye right --out "$TMP/right.csv"
grep -q '^0,0.255000,0.390000$' "$TMP/right.csv" || fail "right.csv: $(head -n 3 "$TMP/right.csv")"
# each eye its own gaze: a five-column trace that a stereo render takes
expect 0 "" -- $G "$D/pupil_binocular.csv" --eye each --out "$TMP/each.csv"
grep -q '^0,0.345000,0.410000,0.255000,0.390000$' "$TMP/each.csv" || fail "each.csv: $(head -n 3 "$TMP/each.csv")"
expect 0 "" -- $R --gaze-trace "$TMP/each.csv" --stereo 10 --frames 2 --fps 60 --out "$TMP/each.png"
expect 0 "" -- $R --gaze-trace "$TMP/both.csv" --frames 2 --fps 60 --out "$TMP/both.png"
expect 2 "--eye middle: expected left, right, both or each" -- $G "$D/pupil_binocular.csv" --eye middle --out "$TMP/x.csv"

# ---- EyeLink ----
expect 0 "" -- $G "$D/eyelink_2000hz.asc" --out "$TMP/2k.csv"
grep -q "40 samples (0 missing), screen 1280x1024, right eye, 2000 Hz" "$TMP/err" || fail "2000 Hz summary: $(cat "$TMP/err")"
grep -q '^0.0005,0.500391,0.500000$' "$TMP/2k.csv" || fail "2k.csv: $(head -n 3 "$TMP/2k.csv")"
expect 0 "" -- $G "$D/eyelink_2000hz.asc.gz" --out "$TMP/2kgz.csv"
grep -q "40 samples (0 missing), screen 1280x1024, right eye, 2000 Hz, gzip-compressed" "$TMP/err" || fail ".gz summary: $(cat "$TMP/err")"
diff <(grep -v '^#' "$TMP/2k.csv") <(grep -v '^#' "$TMP/2kgz.csv") >/dev/null || fail "the .gz recording gives another trace"
head -c 300 "$D/eyelink_2000hz.asc.gz" >"$TMP/cut.asc.gz"
expect 2 "cut.asc.gz: the compressed data ends early" -- $G "$TMP/cut.asc.gz" --out "$TMP/x.csv"
expect 0 "" -- $G "$D/eyelink_trials.asc" --out "$TMP/trials.csv"
grep -q "21 samples (1 missing), screen 1000x1000, left eye, 500 Hz, 1 gap between recording blocks marked missing" "$TMP/err" ||
  fail "trials summary: $(cat "$TMP/err")"
grep -q '^0.02,,$' "$TMP/trials.csv" || fail "trials.csv: the break is not missing: $(sed -n 10,14p "$TMP/trials.csv")"
# a frame in the break is rendered with the gaze unknown: widened, not at an interpolated point
expect 0 "" -- $R --gaze-trace "$TMP/trials.csv" --gaze-missing widen --frames 1 --time 0.5 --out "$TMP/t.png"
expect 0 "" -- $G "$D/eyelink_bino.asc" --eye both --out "$TMP/bboth.csv"
grep -q '^0,0.506250,0.500000$' "$TMP/bboth.csv" || fail "bino --eye both: $(head -n 3 "$TMP/bboth.csv")"
expect 2 "eyelink_mono.asc: the recording has no right-eye samples" -- $G "$D/eyelink_mono.asc" --eye right --out "$TMP/x.csv"
printf 'MSG\t1 DISPLAY_COORDS 0 0 99 99\nSTART\t1 \tLEFT\tRIGHT\tSAMPLES\n1\t1\t2\t3\t...\n' >"$TMP/short.asc"
expect 2 "short.asc:3: expected a sample" -- $G "$TMP/short.asc" --out "$TMP/x.csv"

[ -e "$TMP/x.csv" ] && fail "a failed import left x.csv behind"
ls "$TMP" | grep -q 'tmp\.' && fail "temporary files left in $TMP"
# a Pupil export with its header and no row: refused in one line (the fuzzer found a sort of
# nothing here, which UBSan reports)
head -n 1 "$SRC/tests/data/pupil_gaze_positions.csv" >"$TMP/gaze_positions.csv"
expect 2 "no usable gaze sample" -- $FOVEA gaze import "$TMP/gaze_positions.csv" --out "$TMP/empty.csv"
[ -e "$TMP/empty.csv" ] && fail "a refused import wrote empty.csv"
# ---- tables (--format table) and Tobii Pro Lab exports ----
# table_norm.csv: a quoted note with a comma before the time column; rows 10 ms apart
expect 0 "" -- $G "$D/table_norm.csv" --time time --x gx --y gy --out "$TMP/tab.csv"
grep -q "7 samples (4 missing, 1 dropped: time not increasing), one gaze for both eyes" "$TMP/err" || fail "table summary: $(cat "$TMP/err")"
grep -q '^0.01,0.250000,0.750000$' "$TMP/tab.csv" || fail "tab.csv: $(sed -n 2,4p "$TMP/tab.csv")"
grep -q '^0.02,,$' "$TMP/tab.csv" || fail "tab.csv: the blink is not missing"
expect 0 "" -- $R --gaze-trace "$TMP/tab.csv" --gaze-missing widen --frames 2 --fps 60 --out "$TMP/tab.png"
# pixels of 1920x1080 from the bottom left, ms, both eyes: right eye at 1000 ms (980,560) ->
# 980/1920 = 0.510417, 1 - 560/1080 = 0.481481
expect 0 "" -- $G "$D/table_px_bottomleft.tsv" --format table --time "Time (ms)" --time-unit ms --left-x LX --left-y LY --right-x RX \
  --right-y RY --valid Valid --coords px --screen 1920x1080 --origin bottom-left --out "$TMP/px.csv"
grep -q "4 samples (1 missing), both eyes, screen 1920x1080" "$TMP/err" || fail "px summary: $(cat "$TMP/err")"
grep -q '^0,0.500000,0.500000,0.510417,0.481481$' "$TMP/px.csv" || fail "px.csv: $(sed -n 2p "$TMP/px.csv")"
expect 0 "" -- $R --gaze-trace "$TMP/px.csv" --stereo 10 --frames 2 --fps 60 --out "$TMP/px.png"
expect 2 "--coords px needs the screen" -- $G "$D/table_px_bottomleft.tsv" --time 1 --x 2 --y 3 --coords px --out "$TMP/x.csv"
expect 2 "table_norm.csv: --x gz: no such column; the header has 'note', 'time', 'GX', 'gy'" -- \
  $G "$D/table_norm.csv" --time time --x gz --y gy --out "$TMP/x.csv"
expect 2 "--x and --y both name column 'GX'" -- $G "$D/table_norm.csv" --time time --x gx --y gx --out "$TMP/x.csv"
printf 't,x,y\n0,0.1,0.2\n0.01,0.3,O.4\n' >"$TMP/typo.csv"
expect 2 "typo.csv:3: column 'y': 'O.4' is not a number" -- $G "$TMP/typo.csv" --time t --x x --y y --out "$TMP/x.csv"
: >"$TMP/none.csv"
expect 2 "none.csv: the file is empty" -- $G "$TMP/none.csv" --time t --x x --y y --out "$TMP/x.csv"
expect 2 "not Pupil's gaze_positions.csv (for another table: --format table --time COL --x COL --y COL)" -- \
  $G "$D/table_norm.csv" --out "$TMP/x.csv"
expect 2 "--time-unit min: expected s, ms, us or ns" -- $G "$D/table_norm.csv" --time time --x gx --y gy --time-unit min --out "$TMP/x.csv"
expect 2 "--coords cm: expected norm or px" -- $G "$D/table_norm.csv" --time time --x gx --y gy --coords cm --out "$TMP/x.csv"
expect 2 "--origin centre: expected top-left or bottom-left" -- $G "$D/table_norm.csv" --time time --x gx --y gy --origin centre --out "$TMP/x.csv"
expect 2 "--format excel: expected eyelink, pupil, tobii or table" -- $G "$D/table_norm.csv" --format excel --out "$TMP/x.csv"
# Tobii Pro Lab: found by the .tsv's header, also gzip-compressed; events skipped
expect 0 "" -- $G "$D/tobii_prolab.tsv" --out "$TMP/tobii.csv"
grep -q "5 samples (1 missing), screen 1920x1080, one gaze for both eyes, 2 rows without gaze data skipped" "$TMP/err" ||
  fail "tobii summary: $(cat "$TMP/err")"
grep -q '^0.016667,0.750000,0.750000$' "$TMP/tobii.csv" || fail "tobii.csv: $(sed -n 4p "$TMP/tobii.csv")"
gzip -c "$D/tobii_prolab.tsv" >"$TMP/prolab.tsv.gz"
expect 0 "" -- $G "$TMP/prolab.tsv.gz" --out "$TMP/tobiigz.csv"
diff <(grep -v '^#' "$TMP/tobii.csv") <(grep -v '^#' "$TMP/tobiigz.csv") >/dev/null || fail "the .tsv.gz export gives another trace"
expect 0 "" -- $G "$D/tobii_prolab.tsv" --eye each --out "$TMP/tobii5.csv"
grep -q '^0.016667,,,0.750000,0.750000$' "$TMP/tobii5.csv" || fail "tobii --eye each: $(sed -n 4p "$TMP/tobii5.csv")"
expect 2 "tobii_ms.tsv:2: gaze in pixels, and no recording resolution in the row" -- $G "$D/tobii_ms.tsv" --out "$TMP/x.csv"
expect 0 "" -- $G "$D/tobii_ms.tsv" --screen 640x480 --out "$TMP/tms.csv"
grep -q '^0.0165,1.000000,1.000000$' "$TMP/tms.csv" || fail "tms.csv: $(sed -n 3p "$TMP/tms.csv")"
expect 2 "are for --format table (Tobii's columns are found by name" -- $G "$D/tobii_prolab.tsv" --format tobii --x a --y b --out "$TMP/x.csv"
expect 2 "--coords and --origin are for --format table" -- $G "$D/tobii_prolab.tsv" --origin bottom-left --out "$TMP/x.csv"
expect 0 "" -- $G "$D/tobii_prolab.tsv" --time-unit ms --out "$TMP/tobiims.csv"
grep -q '^8.333,0.250000,0.250000$' "$TMP/tobiims.csv" || fail "tobii --time-unit ms: $(sed -n 3p "$TMP/tobiims.csv")"
expect 2 "table_px_bottomleft.tsv: not a Tobii Pro Lab export" -- $G "$D/table_px_bottomleft.tsv" --out "$TMP/x.csv"
$FOVEA gaze --help | grep -q -- "--left-x COL" || fail "gaze --help lacks the table options"
[ -e "$TMP/x.csv" ] && fail "a refused table import left x.csv behind"
finish
