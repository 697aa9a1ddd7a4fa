# Malformed input of every kind, as a new user would try it (issue 14, item 5): each case exits 2
# with one line naming the file or option and what is wrong, fast, and leaves nothing behind.
. "$(dirname "$0")/lib.sh"
D=$SRC/tests/data
OUT=$TMP/out.png
R="$FOVEA render"
small="--size 8x8 --spp 1 --quiet --out $OUT"

# ---- coordinates, extents and intensities: one limit (fovea/limits.h) everywhere ----
beyond="is beyond +-1e+09, the range the ray kernels take"
expect 2 "--camera-pos 1e19,273,-800: coordinate 1e+19 $beyond" -- $R cornell --camera-pos 1e19,273,-800 $small
expect 2 "--camera-pos 1.9e18,273,-800: coordinate 1.9e+18 $beyond" -- $R cornell --camera-pos 1.9e18,273,-800 $small
expect 2 "--camera-look 0,-1e39,0: coordinate -1e+39 $beyond" -- $R cornell --camera-look 0,-1e39,0 $small
expect 2 "--stereo 1e20: coordinate 1e+20 $beyond" -- $R cornell --stereo 1e20 $small
# an overflowing position is called what it is, not "up vector is parallel to the view direction"
expect 2 "--camera-pos 1e38,1e38,1e38: coordinate 1e+38 $beyond" -- $R cornell --camera-pos 1e38,1e38,1e38 $small
# the CLI's light and the JSON light share the intensity limit
expect 2 "--point-light 0,500,0,3e38,1,1: intensity 3e+38 is outside [0, 1e+20]" -- $R cornell --point-light 0,500,0,3e38,1,1 $small
cat >"$TMP/light.json" <<'J'
{"materials": {"w": {}}, "objects": [{"box": {"half": [1, 1, 1]}, "material": "w"}],
 "lights": [{"pos": [0, 3, 0], "intensity": [3e38, 1, 1]}]}
J
expect 2 "light.json: lights[0].intensity: intensity 3e+38 is outside [0, 1e+20]" -- $R "$TMP/light.json" $small
# a scene camera and a trace camera at 1e19
cat >"$TMP/cam.json" <<'J'
{"materials": {"w": {}}, "objects": [{"box": {"half": [1, 1, 1]}, "material": "w"}],
 "camera": {"pos": [1e19, 0, 5], "look": [0, 0, 0]}}
J
expect 2 "cam.json: camera.pos: coordinate 1e+19 $beyond" -- $R "$TMP/cam.json" $small
printf '0,278,273,-800,278,273,0\n1,1e19,273,-800,278,273,0\n' >"$TMP/cam.csv"
expect 2 "cam.csv:2: coordinate 1e+19 $beyond" -- $R cornell --camera-trace "$TMP/cam.csv" $small
# extents: the field and the object are named
cat >"$TMP/ext.json" <<'J'
{"materials": {"w": {}}, "objects": [{"sphere": {"center": [1e30, 0, 0], "radius": 1}, "material": "w"}]}
J
expect 2 "ext.json: objects[0].sphere.center: coordinate 1e+30 $beyond" -- $R "$TMP/ext.json" $small
cat >"$TMP/anim.json" <<'J'
{"materials": {"w": {}}, "objects": [{"name": "runaway", "box": {"half": [1, 1, 1]}, "material": "w",
  "animation": [{"time": 0}, {"time": 1, "translate": [1e9, 0, 0], "scale": 1000}]}]}
J
expect 2 "object 'runaway' (as animated): bounds: coordinate" -- $R "$TMP/anim.json" $small
cat >"$TMP/point.json" <<'J'
{"materials": {"w": {}}, "objects": [{"quad": [[0, 0, 0], [0, 0, 0], [0, 0, 0], [0, 0, 0]], "material": "w"}]}
J
expect 2 "point.json: objects[0]: mesh 'objects[0]': no valid triangles" -- $R "$TMP/point.json" $small
# an argument with a newline stays on one line
expect 2 "--camera-pos 1\\n2: expected x,y,z" -- $R cornell --camera-pos "$(printf '1\n2')" $small
# a mesh reaching the edge of the range renders: its framing camera stops at the edge (a fuzz
# finding: the camera framing it was put at 1.37e15 and refused)
printf 'v 1e9 0 0\nv 0 0 0\nv 0 0 1e9\nf 1 2 3\n' >"$TMP/edge.obj"
expect 0 "" -- $R "$TMP/edge.obj" $small
printf 'v 1e9 0 1e9\nv 0 0 1e9\nv 0 1e9 1e9\nf 1 2 3\n' >"$TMP/edge2.obj"
expect 0 "" -- $R "$TMP/edge2.obj" $small
# at the limit it renders
expect 0 "" -- $R cornell --camera-pos 1e9,273,-800 $small
rm -f "$OUT"

# ---- JSON: a duplicate key; a raw control byte in a key stays on one line ----
cat >"$TMP/dup.json" <<'J'
{"materials": {"w": {"albedo": [1, 0, 0], "albedo": [0, 1, 0]}}, "objects": [{"box": {"half": [1, 1, 1]}, "material": "w"}]}
J
expect 2 "dup.json: materials.w: field 'albedo' is given twice" -- $R "$TMP/dup.json" $small
printf '{"materials": {"w": {}}, "objects": [{"bo\nx": {"half": [1, 1, 1]}, "material": "w"}]}' >"$TMP/ctl.json"
expect 2 "unknown field 'bo\\nx'" -- $R "$TMP/ctl.json" $small
printf '{"materials": {"w": {}}, "objects": [{"bo\001x": {"half": [1, 1, 1]}, "material": "w"}]}' >"$TMP/ctl2.json"
expect 2 "unknown field 'bo\\x01x'" -- $R "$TMP/ctl2.json" $small

# ---- fovea bench --check refuses what a run would refuse ----
scen() { printf '{"scene": "%s", "size": [16, 16], "reference": {"method": "pt"%s}, "methods": [{"method": "pt"%s}]%s}\n' "$@" >"$TMP/s.json"; }
B="$FOVEA bench --check"
scen cornell '' '' ''
expect 0 "" -- $B "$TMP/s.json"
scen cornell ', "params": {"spp": -4}' '' ''
expect 2 "s.json: reference: " -- $B "$TMP/s.json"
scen cornell '' ', "params": {"bogus": 1}' ''
expect 2 "unknown parameter 'bogus'" -- $B "$TMP/s.json"
scen no-such-scene.json '' '' ''
expect 2 "s.json: scene: cannot open scene" -- $B "$TMP/s.json"
scen cornell '' '' ', "camera_path": [{"time": 0, "pos": [0, 0, 0], "look": [0, 0, -1]}, {"time": 1, "pos": [0, 0, 0], "look": [0, 0, 0]}], "frames": 2, "fps": 1'
expect 2 "s.json: frame 1 (time 1), camera_path: camera: look-at point equals the position" -- $B "$TMP/s.json"
scen cornell '' '' ', "match": [{"method": "pt", "param": "spp", "values": [-2, 1], "target": "pt"}]'
expect 2 "match[0] (spp=-2)" -- $B "$TMP/s.json"
[ -e bench-out ] && fail "bench --check wrote bench-out"

# ---- fovea compare counts NaN pixels instead of calling two NaN images identical ----
printf 'PF\n2 1\n-1.0\n' >"$TMP/nan.pfm"
printf '\000\000\300\177\000\000\300\177\000\000\300\177\000\000\300\177\000\000\300\177\000\000\300\177' >>"$TMP/nan.pfm"
"$FOVEA" compare "$TMP/nan.pfm" "$TMP/nan.pfm" >"$TMP/cmp" 2>"$TMP/cmp.err" || fail "compare of two NaN images failed"
grep -q "2 of 2 in .*nan.pfm, 2 in" "$TMP/cmp.err" || fail "no NaN warning: $(cat "$TMP/cmp.err")"
awk '$1 == "all" && $NF == 2 {ok = 1} END {exit !ok}' "$TMP/cmp" || fail "the table does not count 2 NaN pixels: $(cat "$TMP/cmp")"
"$FOVEA" compare "$TMP/nan.pfm" "$TMP/nan.pfm" --json 2>/dev/null | grep -q '"nonfinite_pixels": {"ref": 2, "test": 2}' || fail "JSON lacks the NaN count"

# ---- a mesh file that makes assimp run away or abort: exit 2, fast ----
printf 'OFF\n3 1000000000 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$TMP/oom.off"
t0=$(date +%s)
expect 2 "oom.off': its header declares 1000000003 elements" -- $R "$TMP/oom.off" $small
# a PLY header cut short makes assimp loop: refused before it runs
printf 'ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n' >"$TMP/cut.ply"
expect 2 "cut.ply': PLY header line" -- $R "$TMP/cut.ply" $small
# a free-text header line (Blender 2.47 wrote one without "comment"): the reader skips it, so
# does the check (issue 25, item 3); a mangled declaration is still refused
printf 'ply\nformat ascii 1.0\nCreated by a modeller, source file: \nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n' >"$TMP/text.ply"
expect 0 "" -- $R "$TMP/text.ply" --size 8x8 --spp 1 --quiet --out "$TMP/text.png"
printf 'ply\nformat ascii 1.0\nelement vertex three\nproperty float x\nend_header\n' >"$TMP/mangled.ply"
expect 2 "mangled.ply': PLY header line 3" -- $R "$TMP/mangled.ply" $small
# an OFF file cut short: assimp's own assertion aborts; the child process reports it
printf 'OFF\n4 2 0\n0 0 0' >"$TMP/abort.off"
expect 2 "abort.off': the mesh importer (assimp): crashed (signal 6" -- $R "$TMP/abort.off" $small
# a binary PLY with too few bytes: assimp reads out of bounds (a segmentation fault in the child)
printf 'ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\0\0\0\0\0\0\0\0\0\0\0\0\0\0\0\200' >"$TMP/short.ply"
# (under AddressSanitizer the child reports the fault and exits instead of dying of the signal)
expect 2 "short.ply': the mesh importer (assimp): " -- $R "$TMP/short.ply" $small
t1=$(date +%s)
[ $((t1 - t0)) -lt 30 ] || fail "the runaway meshes took $((t1 - t0)) s"
[ -e "$OUT" ] && fail "a refused input left $OUT behind"

# ---- gaze from eye trackers: import, missing samples, policy ----
G="$FOVEA gaze import"
expect 0 "" -- $G "$D/eyelink_mono.asc" --out "$TMP/mono.csv"
grep -q "7 samples (3 missing), screen 1920x1080" "$TMP/err" || fail "mono summary: $(cat "$TMP/err")"
# 1002: x = 1919 / 1920; 1006..1008 in the blink, 1010 off the screen: missing (empty fields)
grep -q '^0.002,0.999479,0.000000$' "$TMP/mono.csv" || fail "mono.csv: $(cat "$TMP/mono.csv")"
[ "$(grep -c ',,$' "$TMP/mono.csv")" = 3 ] || fail "mono.csv should have 3 missing samples"
expect 0 "" -- $G "$D/eyelink_bino.asc" --out "$TMP/bino.csv"
grep -q '^0.008,0.250000,0.250000,,$' "$TMP/bino.csv" || fail "bino.csv: right eye in a blink at 28 ms: $(cat "$TMP/bino.csv")"
expect 0 "" -- $G "$D/pupil_gaze_positions.csv" --out "$TMP/pupil.csv"
# the two eyes' rows at 100.1 s are one sample, their mean (docs/gaze.md, "Which eye"); y flipped
grep -q "5 samples (2 missing), one gaze for both eyes (1 pair of rows" "$TMP/err" || fail "pupil summary: $(cat "$TMP/err")"
grep -q '^0.1,0.255000,0.255000$' "$TMP/pupil.csv" || fail "pupil.csv: y flipped: $(cat "$TMP/pupil.csv")"
expect 0 "" -- $G "$D/pupil_gaze_positions.csv" --out "$TMP/pupil2.csv" --confidence 0.05
grep -q '^0.2,0.900000,0.100000$' "$TMP/pupil2.csv" || fail "a lower threshold keeps the 0.1-confidence sample"
# the traces drive renders, with either policy
expect 0 "" -- $R cornell --gaze-trace "$TMP/mono.csv" --frames 2 --fps 125 --size 8x8 --spp 1 --quiet --out "$TMP/m.png"
expect 0 "" -- $R cornell --gaze-trace "$TMP/bino.csv" --gaze-missing widen --stereo 10 --size 8x8 --spp 1 --quiet --out "$TMP/b.png"
expect 2 "--gaze-missing blink" -- $R cornell --gaze-missing blink $small
# a jump of the clock to 1e19 s: times that would print equal are dropped, the trace still loads
# (a fuzz finding: the imported trace was refused)
printf 'gaze_timestamp,confidence,norm_pos_x,norm_pos_y\n100,1,0.5,0.5\n1e19,1,0.5,0.5\n1.0000000001e19,1,0.4,0.4\n' >"$TMP/jump.csv"
expect 0 "" -- $G "$TMP/jump.csv" --out "$TMP/jump-trace.csv"
grep -q "2 samples (0 missing, 1 dropped" "$TMP/err" || fail "jump summary: $(cat "$TMP/err")"
expect 0 "" -- $R cornell --gaze-trace "$TMP/jump-trace.csv" --size 8x8 --spp 1 --quiet --out "$TMP/j.png"
# bad recordings: one line naming the file, no output
printf 'MSG\t1 TRIALID\n1\t1\t2\t3\n' >"$TMP/nosize.asc"
expect 2 "nosize.asc: no usable DISPLAY_COORDS" -- $G "$TMP/nosize.asc" --out "$TMP/x.csv"
printf 'a,b\n1,2\n' >"$TMP/notpupil.csv"
expect 2 "notpupil.csv: the header lacks gaze_timestamp" -- $G "$TMP/notpupil.csv" --out "$TMP/x.csv"
printf 'gaze_timestamp,confidence,norm_pos_x,norm_pos_y\n1,0.1,0.5,0.5\n' >"$TMP/lowconf.csv"
expect 2 "lowconf.csv: no usable gaze sample" -- $G "$TMP/lowconf.csv" --out "$TMP/x.csv"
[ -e "$TMP/x.csv" ] && fail "a failed import left x.csv behind"
ls "$TMP" | grep -q 'tmp\.' && fail "temporary files left in $TMP"
# a material library with bytes where numbers belong: assimp's error names neither file nor line;
# the message names the .mtl and its line, with the bytes escaped (item 10)
printf 'mtllib g.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n' >"$TMP/m.obj"
printf 'newmtl x\nKd 0.5 0.5 0.5\nKs \377\376\001 garbage\n' >"$TMP/g.mtl"
expect 2 "scene '$TMP/m.obj': material library 'g.mtl', line 3: Ks wants a number, not '\xff\xfe\x01'" -- $R "$TMP/m.obj" $small
printf 'newmtl x\nNs 10\nKd spectral some.rfl\n' >"$TMP/g.mtl"
expect 2 "material library 'g.mtl', line 3: Kd wants a number, not 'spectral'" -- $R "$TMP/m.obj" $small
printf 'newmtl x\nNs 10\nKd 1 1 1\n' >"$TMP/g.mtl"
expect 0 "" -- $R "$TMP/m.obj" $small

finish
