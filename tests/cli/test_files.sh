# fovea CLI: inputs must be regular files (a device reads forever, a FIFO blocks the open), lines
# are bounded, and outputs follow symbolic links, refuse device nodes and keep the system's reason
# for a failed write (issue 25, items 7 and 8; core/fileio.h). Nothing under /dev is written: the
# device node is one this test makes in its own folder; /dev/zero is only named as an input.
. "$(dirname "$0")/lib.sh"

R="$FOVEA render cornell --size 8x8 --quiet"
mkfifo "$TMP/fifo" || fail "mkfifo failed"

# within: CODE NEEDLE -- command...: as expect, and done within a second (timeout 5 stops a hang).
within() {
  local t0 t1
  t0=$(date +%s%N)
  expect "$1" "$2" -- timeout 5 "${@:4}"
  t1=$(date +%s%N)
  [ $(((t1 - t0) / 1000000)) -lt 1000 ] || fail "'${*:4}' took $(((t1 - t0) / 1000000)) ms"
}

# ---- inputs: /dev/zero and a FIFO ----
for x in /dev/zero "$TMP/fifo"; do
  kind="a character device"
  [ "$x" = "$TMP/fifo" ] && kind="a FIFO"
  within 2 "gaze trace '$x': not a regular file ($kind)" -- $R --out "$TMP/o.png" --gaze-trace "$x"
  within 2 "camera trace '$x': not a regular file ($kind)" -- $R --out "$TMP/o.png" --camera-trace "$x"
  within 2 "scene '$x': not a regular file ($kind)" -- $FOVEA render "$x" --size 8x8 --out "$TMP/o.png"
  within 2 "recording '$x': not a regular file ($kind)" -- $FOVEA gaze import "$x" --out "$TMP/g.csv"
  within 2 "recording '$x': not a regular file ($kind)" -- $FOVEA gaze import "$x" --format eyelink --out "$TMP/g.csv"
  within 2 "scenario '$x': not a regular file ($kind)" -- $FOVEA bench --check "$x"
  printf '{"materials": {"w": {}}, "objects": [{"box": {"half": [1, 1, 1]}, "material": "w"}], "camera_path": "%s"}\n' "$x" >"$TMP/cp.json"
  within 2 "cp.json: camera_path: cannot open camera trace '$x': not a regular file ($kind)" -- $FOVEA render "$TMP/cp.json" --size 8x8 --out "$TMP/o.png"
  printf '{"materials": {"w": {}}, "objects": [{"box": {"half": [1, 1, 1]}, "material": "w"}], "gaze": {"trace": "%s"}}\n' "$x" >"$TMP/gp.json"
  within 2 "gp.json: gaze.trace: cannot open gaze trace '$x': not a regular file ($kind)" -- $FOVEA render "$TMP/gp.json" --size 8x8 --out "$TMP/o.png"
  printf '{"materials": {"w": {}}, "objects": [{"mesh": "%s", "material": "w"}]}\n' "$x" >"$TMP/mesh.json"
  within 2 "objects[0].mesh: cannot open mesh '$x': not a regular file ($kind)" -- $FOVEA render "$TMP/mesh.json" --size 8x8 --out "$TMP/o.png"
  printf '{"materials": {"w": {"albedo_texture": "%s"}}, "objects": [{"box": {"half": [1, 1, 1]}, "material": "w"}]}\n' "$x" >"$TMP/tex.json"
  within 2 "albedo_texture: cannot open texture '$x': not a regular file ($kind)" -- $FOVEA render "$TMP/tex.json" --size 8x8 --out "$TMP/o.png"
done
expect 0 "" -- $R --out "$TMP/a.png"
within 2 "image '/dev/zero': not a regular file (a character device)" -- $FOVEA compare "$TMP/a.png" /dev/zero
within 2 "image '$TMP/fifo': not a regular file (a FIFO)" -- $FOVEA compare "$TMP/fifo" "$TMP/a.png"
within 2 "scene '$TMP': not a regular file (a directory)" -- $FOVEA render "$TMP" --size 8x8 --out "$TMP/o.png"
[ -p "$TMP/fifo" ] || fail "the FIFO is gone"

# ---- a line longer than 64 KiB is refused naming file:line; a usual trace still reads ----
{ echo "# time,x,y"; head -c 100000 /dev/zero | tr '\0' '1'; echo; } >"$TMP/long.csv"
within 2 "long.csv:2: line longer than 65536 bytes" -- $R --out "$TMP/o.png" --gaze-trace "$TMP/long.csv"
{ echo "MSG 0 DISPLAY_COORDS 0 0 99 99"; head -c 100000 /dev/zero | tr '\0' '1'; echo; } >"$TMP/long.asc"
within 2 "long.asc:2: line longer than 65536 bytes" -- $FOVEA gaze import "$TMP/long.asc" --out "$TMP/g.csv"
[ -e "$TMP/g.csv" ] && fail "a refused import left its output"
printf '0,0.5,0.5\n1,0.25,0.75\n' >"$TMP/ok.csv"
expect 0 "" -- $R --out "$TMP/o.png" --gaze-trace "$TMP/ok.csv"

# ---- outputs: a symbolic link is written through ----
mkdir -p "$TMP/real" "$TMP/links"
ln -s ../real/img.pfm "$TMP/links/rel.pfm"
expect 0 "" -- $R --out "$TMP/links/rel.pfm"
[ -L "$TMP/links/rel.pfm" ] || fail "the relative link was replaced"
[ -f "$TMP/real/img.pfm" ] && [ -s "$TMP/real/img.pfm" ] || fail "the link's target was not written"
ln -s "$TMP/real/abs.png" "$TMP/links/abs.png"
ln -s abs.png "$TMP/links/chain.png"
expect 0 "" -- $R --out "$TMP/links/chain.png"
[ -L "$TMP/links/chain.png" ] && [ -L "$TMP/links/abs.png" ] || fail "a link of the chain was replaced"
head -c 8 "$TMP/real/abs.png" | od -An -c | grep -q 'P   N   G' || fail "the chain's target is not the PNG"
ln -s ../real/trace.csv "$TMP/links/trace.csv"
expect 0 "" -- $FOVEA gaze import "$SRC/tests/data/eyelink_mono.asc" --out "$TMP/links/trace.csv" --quiet
[ -L "$TMP/links/trace.csv" ] && [ -s "$TMP/real/trace.csv" ] || fail "gaze import did not write through the link"
ls "$TMP/real" "$TMP/links" | grep -q '\.tmp\.' && fail "a temporary file was left"

# ---- outputs: a device node, a FIFO or a folder is refused and left as it was ----
if mknod "$TMP/node.png" c 1 3 2>/dev/null; then
  expect 2 "cannot write '$TMP/node.png': not a regular file (a character device)" -- $R --out "$TMP/node.png"
  [ -c "$TMP/node.png" ] || fail "the device node was replaced"
  ln -s node.png "$TMP/to-node.png"
  expect 2 "cannot write '$TMP/to-node.png': not a regular file (a character device)" -- $R --out "$TMP/to-node.png"
  [ -c "$TMP/node.png" ] && [ -L "$TMP/to-node.png" ] || fail "the device node or its link was replaced"
else
  echo "skip: mknod failed (not root?): the device-node output is not checked"
fi
mkfifo "$TMP/out.pfm"
within 2 "cannot write '$TMP/out.pfm': not a regular file (a FIFO)" -- $R --out "$TMP/out.pfm"
[ -p "$TMP/out.pfm" ] || fail "the FIFO output was replaced"
mkdir "$TMP/dir.png"
expect 2 "cannot write '$TMP/dir.png': not a regular file (a directory)" -- $R --out "$TMP/dir.png"
within 2 "cannot write '$TMP/fifo': not a regular file (a FIFO)" -- $FOVEA gaze import "$TMP/ok.csv" --out "$TMP/fifo"
ls "$TMP" | grep -q '\.tmp\.' && fail "a temporary file was left"

# ---- a failed write keeps its reason: a file size limit (EFBIG) stands in for a full disk ----
# (SIGXFSZ ignored, so write() fails with EFBIG instead of killing the process.)
( trap '' XFSZ; ulimit -f 1; exec $FOVEA render cornell --size 64x64 --quiet --out "$TMP/big.pfm" ) >"$TMP/out" 2>"$TMP/err"
rc=$?
[ "$rc" = 2 ] || fail "a PFM write over the size limit exited $rc, expected 2: $(cat "$TMP/err")"
grep -qF "cannot write '$TMP/big.pfm': File too large" "$TMP/err" || fail "the failed PFM write lost its reason: $(cat "$TMP/err")"
[ -e "$TMP/big.pfm" ] && fail "a failed write left big.pfm"
ls "$TMP" | grep -q '\.tmp\.' && fail "a failed write left its temporary file"
# the same for a PNG, which libpng alone would report as "Write Error"
( trap '' XFSZ; ulimit -f 1; exec $FOVEA render cornell --size 256x256 --spp 1 --quiet --out "$TMP/big.png" ) >"$TMP/out" 2>"$TMP/err"
rc=$?
[ "$rc" = 2 ] || fail "a PNG write over the size limit exited $rc, expected 2: $(cat "$TMP/err")"
grep -qF "cannot write '$TMP/big.png': File too large" "$TMP/err" || fail "the failed PNG write lost its reason: $(cat "$TMP/err")"
[ -e "$TMP/big.png" ] && fail "a failed write left big.png"
ls "$TMP" | grep -q '\.tmp\.' && fail "a failed PNG write left its temporary file"

finish
