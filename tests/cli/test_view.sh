# The interactive viewer (fovea-view, built only with SDL2): under a virtual X server a script
# takes screenshots, and the screenshots show that the scene is drawn, that Tab switches the
# method, and that the overlay's fovea circle follows the scripted gaze. Without a display and
# with an unknown method it fails like `fovea render`: exit 2, one line.
. "$(dirname "$0")/lib.sh"
VIEW="$(dirname "$FOVEA")/fovea-view"
if [ ! -x "$VIEW" ]; then
  # skipping is right only when the build could not have made it
  if pkg-config --exists sdl2 2>/dev/null; then
    fail "SDL2 is installed but $VIEW was not built"
    finish
  fi
  echo "SKIP: fovea-view not built (no SDL2)"
  exit 0
fi
command -v xvfb-run >/dev/null || { fail "xvfb-run is missing (scripts/install-deps --with-tests installs xvfb)"; finish; }
# Under the sanitizers (scripts/test's second pass), LeakSanitizer reports at exit what D-Bus and the
# X11 libraries SDL loads (and unloads again in SDL_Quit) keep: 1.2 KB in libdbus and in modules it
# can no longer name, so no suppression can match them, and the viewer's exit status becomes 23.
# Leak checking stays on for everything else; AddressSanitizer's other checks stay on here.
if [ "${FOVEA_SANITIZED:-0}" = 1 ]; then
  export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
fi

# bad input: the same message as fovea render, exit 2, before any window opens
expect 2 "unknown method 'nope' (known: pt," -- "$VIEW" cornell --method nope
"$FOVEA" render cornell --method nope 2>"$TMP/render.err"
sed 's/^fovea render:/fovea view:/' "$TMP/render.err" | cmp -s - "$TMP/err" || fail "fovea view and fovea render word an unknown method differently"
expect 2 "unknown parameter 'foo'" -- "$VIEW" cornell --method vpolar --param foo=1
expect 2 "--param svgf_alpha=0.5: svgf_alpha is already set (to 0.3)" -- "$VIEW" cornell --method vpolar --param svgf_alpha=0.3 --param svgf_alpha=0.5
expect 2 "method 'fpm' does not run on device cuda (methods that do: pt, vpolar, cartesian, cartesian-full, linear-falloff, log-polar, sdf-gt, sdf-relaxed, ipr, fipr)" -- "$VIEW" cornell --method fpm --device cuda
expect 2 "device 'gpu' is not one of cpu, portable, cuda, auto" -- "$VIEW" cornell --method pt --device gpu
expect 2 "no display" -- env -u DISPLAY -u SDL_VIDEODRIVER -u WAYLAND_DISPLAY "$VIEW" cornell --method vpolar
expect 2 "unknown or incomplete command 'jump'" -- "$VIEW" --script /dev/stdin <<<"0 jump"
expect 2 "--frame-view sideways: expected front" -- "$VIEW" --frame-view sideways
expect 2 "move needs R U F" -- "$VIEW" --script /dev/stdin <<<"0 move 1 nan 2"
expect 2 "look needs YAW PITCH" -- "$VIEW" --script /dev/stdin <<<"0 look 400 0"

# frames are counted from 0; keys and gaze act before their frame, screenshots after it
cat >"$TMP/s.txt" <<SCRIPT
0 key O
0 mouse 0.25 0.5
2 screenshot $TMP/a.png
3 mouse 0.75 0.5
5 screenshot $TMP/b.png
6 key Tab
8 screenshot $TMP/c.png
9 quit
SCRIPT
# for the method switch, a second run shows the same frames bare: no overlay, no text (H)
cat >"$TMP/bare.txt" <<SCRIPT
0 key H
0 mouse 0.5 0.5
2 screenshot $TMP/o.png
3 screenshot $TMP/p.png
4 key shift+Tab
6 screenshot $TMP/q.png
7 screenshot $TMP/q2.png
8 move 0 0 150
8 look 15 0
9 screenshot $TMP/r.png
10 quit
SCRIPT
(cd "$TMP" && xvfb-run -a "$VIEW" cornell --method vpolar --size 320x180 --threads 2 --script "$TMP/s.txt" --fps-log "$TMP/fps.csv") \
  >"$TMP/run.out" 2>&1 || fail "the scripted session failed: $(cat "$TMP/run.out")"
(cd "$TMP" && xvfb-run -a "$VIEW" cornell --method vpolar --size 320x180 --threads 2 --script "$TMP/bare.txt") \
  >"$TMP/run2.out" 2>&1 || fail "the second scripted session failed: $(cat "$TMP/run2.out")"
[ "$(grep -c '' "$TMP/fps.csv" 2>/dev/null)" = 11 ] || fail "--fps-log should hold a header and 10 frames: $(cat "$TMP/fps.csv" 2>/dev/null)"
# each line's display time is its own column, and render plus display fit in the frame
awk -F, 'NR == 1 { ok = ($3 == "render_ms" && $4 == "frame_ms" && $5 == "display_ms"); next }
  { if (!($5 > 0 && $3 + $5 <= $4 + 0.02)) ok = 0 } END { exit !ok }' "$TMP/fps.csv" ||
  fail "--fps-log: display_ms missing or render + display beyond the frame: $(cat "$TMP/fps.csv")"

# --device: pt's frames from the portable backend (the GPU's kernel on the CPU) reach the window.
cat >"$TMP/dev.txt" <<SCRIPT
1 screenshot $TMP/dev.png
2 quit
SCRIPT
(cd "$TMP" && xvfb-run -a "$VIEW" cornell --method pt --device portable --size 160x90 --threads 2 --script "$TMP/dev.txt") \
  >"$TMP/dev.out" 2>&1 || fail "the session on --device portable failed: $(cat "$TMP/dev.out")"
[ -s "$TMP/dev.png" ] || fail "the session on --device portable took no screenshot"

# closing mid-frame: SDL turns SIGTERM into the same quit event as the window's close button; ir's
# first 640x360 frame takes seconds, the progress callback sees the quit and cancels it: exit 0 at once
xvfb-run -a sh -c '"$0" cornell-fir --method ir --fps-log "$1" & p=$!; sleep 2; t0=$(date +%s%N); kill -TERM $p; wait $p; rc=$?
  echo "$rc $(( ($(date +%s%N) - t0) / 1000000 ))"' "$VIEW" "$TMP/cancel.csv" >"$TMP/cancel.out" 2>&1
read -r crc cms <"$TMP/cancel.out"
[ "$crc" = 0 ] || fail "closing during a frame: exit $crc, expected 0: $(cat "$TMP/cancel.out")"
[ "${cms:-99999}" -lt 1500 ] || fail "closing during a frame took ${cms} ms: the frame was not cancelled"
[ "$(grep -c '' "$TMP/cancel.csv")" = 1 ] || fail "closing during the first frame still logged a frame: $(cat "$TMP/cancel.csv")"

python3 - "$TMP" <<'PY' || fail "the screenshots are wrong (above)"
import struct, sys, zlib

def read_png(path):
    # 8-bit RGB or RGBA, non-interlaced: what fv_image_write produces
    data = open(path, 'rb').read()
    assert data[:8] == b'\x89PNG\r\n\x1a\n', path
    pos, idat = 8, b''
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b'IHDR':
            w, h, depth, ctype = struct.unpack('>IIBB', body[:10])
        elif kind == b'IDAT':
            idat += body
        pos += 12 + n
    assert depth == 8 and ctype in (2, 6), (path, depth, ctype)
    bpp = 3 if ctype == 2 else 4
    raw, stride = zlib.decompress(idat), w * bpp
    rows, prev = [], bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * bpp:x * bpp + 3]) for x in range(w)])
        prev = line
    return w, h, rows

tmp = sys.argv[1]
ok = True
def check(cond, msg):
    global ok
    if not cond:
        print('FAIL:', msg)
        ok = False

FOVEA = (255, 0, 255)
for name, gx in (('a', 0.25), ('b', 0.75)):
    w, h, px = read_png(f'{tmp}/{name}.png')
    check((w, h) == (320, 180), f'{name}.png is {w}x{h}, not the window size 320x180')
    # (1) the scene is drawn: not black, varied
    lum = [sum(p) / 3 for row in px[20:150] for p in row]
    mean = sum(lum) / len(lum)
    var = sum((l - mean) ** 2 for l in lum) / len(lum)
    check(mean > 20 and var > 100, f'{name}.png looks empty: mean {mean:.1f}, variance {var:.1f}')
    # (3) the fovea circle is around the scripted gaze, and nowhere near the other one
    pts = [(x, y) for y, row in enumerate(px) for x, p in enumerate(row) if p == FOVEA]
    check(len(pts) > 30, f'{name}.png has {len(pts)} pixels of the fovea colour')
    if pts:
        cx = sum(p[0] for p in pts) / len(pts); cy = sum(p[1] for p in pts) / len(pts)
        check(abs(cx - gx * w) < 4 and abs(cy - 0.5 * h) < 4, f'{name}.png: fovea circle centred at ({cx:.1f}, {cy:.1f}), gaze at ({gx * w:.1f}, {0.5 * h:.1f})')
        other = (1 - gx) * w
        near = [p for p in pts if abs(p[0] - other) < 40]
        check(not near, f'{name}.png: {len(near)} fovea-colour pixels near the old gaze x={other:.0f}')

# (2) Shift-Tab (vpolar -> fpm) changes the image: more than two frames of the same method differ (their noise)
def mean_diff(x, y):
    _, _, p = read_png(f'{tmp}/{x}.png')
    _, _, q = read_png(f'{tmp}/{y}.png')
    d = sum(abs(a - b) for ra, rb in zip(p, q) for pa, pb in zip(ra, rb) for a, b in zip(pa, pb))
    return d / (len(p) * len(p[0]) * 3)
same, switched = mean_diff('o', 'p'), mean_diff('p', 'q')
print(f'mean difference per channel: {same:.2f} between two frames of one method, {switched:.2f} across Tab')
check(switched > 2 * same + 1.0, 'Tab did not change the image')
# (4) the script's move/look fly the camera: the view changes more than between two still frames
still, flown = mean_diff('q', 'q2'), mean_diff('q2', 'r')
print(f'mean difference per channel: {still:.2f} between two still frames, {flown:.2f} after move + look')
check(flown > 2 * still + 1.0, 'move/look did not move the camera')
sys.exit(0 if ok else 1)
PY
finish
