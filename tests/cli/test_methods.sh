# `fovea methods`: the registry's description of every method, as text and as JSON. The JSON must
# hold together: every method in one family, baselines that name other registered methods and end
# at the one reference without a cycle, a baseline for every foveated method, defaults within their
# declared ranges or choices, main parameters whose steps are valid and hold the default; NAME
# --json is that method's entry; an unknown name or option is refused in one line with exit 2; the
# text lists the same methods and prints each parameter of one. A few entries are checked by hand
# against the code (pt, fpm, ppm, vpolar, fipr).
. "$(dirname "$0")/lib.sh"

expect 0 "" -- "$FOVEA" methods --json
cp "$TMP/out" "$TMP/all.json"
expect 0 "" -- "$FOVEA" methods fpm --json
cp "$TMP/out" "$TMP/fpm.json"
expect 0 "" -- "$FOVEA" methods --json vpolar
cp "$TMP/out" "$TMP/vpolar.json"
expect 0 "" -- "$FOVEA" methods
cp "$TMP/out" "$TMP/list.txt"
expect 0 "" -- "$FOVEA" methods fipr
cp "$TMP/out" "$TMP/fipr.txt"

expect 2 "unknown method 'nope' (known: pt," -- "$FOVEA" methods nope --json
[ -s "$TMP/out" ] && fail "methods nope --json wrote to stdout: $(head -c 200 "$TMP/out")"
expect 2 "unknown method 'nope'" -- "$FOVEA" methods nope
expect 2 "unknown option '--yaml'" -- "$FOVEA" methods --yaml
expect 2 "too many arguments" -- "$FOVEA" methods pt fpm

python3 - "$TMP" <<'PY' || fail "the methods JSON is inconsistent (above)"
import json, math, sys

tmp = sys.argv[1]
doc = json.load(open(f'{tmp}/all.json'))
bad = []
def check(cond, msg):
    if not cond:
        bad.append(msg)

methods = {m['name']: m for m in doc['methods']}
names = [m['name'] for m in doc['methods']]
check(len(names) == len(methods) and len(names) >= 18, f'{len(names)} methods, names {names}')

# families: every method in exactly one, the one its entry names
seen = {}
for f in doc['families']:
    check(f['name'] and f['methods'], f'empty family {f}')
    for n in f['methods']:
        check(n not in seen, f'{n} in two families')
        seen[n] = f['name']
check(set(seen) == set(names), f'methods without a family: {set(names) - set(seen)}')
for n, m in methods.items():
    check(seen.get(n) == m['family'], f'{n}: family {m["family"]} but listed under {seen.get(n)}')
check({'path tracing', 'photon mapping', 'instant radiosity', 'sphere tracing'} <= {f['name'] for f in doc['families']},
      f'families {[f["name"] for f in doc["families"]]}')

# baselines: registered, never itself, ending at the one method without a baseline
roots = [n for n, m in methods.items() if m['baseline'] is None]
check(roots == ['pt'], f'methods without a baseline: {roots}')
for n, m in methods.items():
    check(not m['foveated'] or m['baseline'], f'{n} is foveated and has no baseline')
    at, hops = n, 0
    while methods[at]['baseline'] is not None and hops <= len(methods):
        b = methods[at]['baseline']
        check(b in methods, f'{at}: baseline {b} is not a method')
        check(b != at, f'{at} is its own baseline')
        if b not in methods or b == at:
            break
        at, hops = b, hops + 1
    check(hops <= len(methods), f'{n}: the chain of baselines has a cycle')

def valid(p, v):
    t = p['type']
    if 'choices' in p and v not in p['choices']:
        return False
    if t in ('int', 'float'):
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            return False
        if t == 'int' and v != int(v):
            return False
        lo_ok = v > p['min'] if p['min_open'] else v >= p['min']
        hi_ok = v < p['max'] if p['max_open'] else v <= p['max']
        return lo_ok and hi_ok
    if t == 'bool':
        return isinstance(v, bool)
    return isinstance(v, str)

for n, m in methods.items():
    check(m['devices'][0] == 'cpu' and set(m['devices']) <= {'cpu', 'portable', 'cuda'}, f'{n}: devices {m["devices"]}')
    check(isinstance(m['warmup_frames'], int) and m['warmup_frames'] >= 0, f'{n}: warmup_frames {m["warmup_frames"]}')
    check((m['spp_param'] is None) != (m['spp_instead'] is None), f'{n}: spp_param {m["spp_param"]}, spp_instead {m["spp_instead"]}')
    keys = [p['key'] for p in m['parameters']]
    check(len(keys) == len(set(keys)), f'{n}: a key twice in {keys}')
    check(m['spp_param'] is None or m['spp_param'] in keys, f'{n}: spp_param {m["spp_param"]} not a parameter')
    for p in m['parameters']:
        check(p['type'] in ('int', 'float', 'bool', 'choice', 'string'), f'{n}.{p["key"]}: type {p["type"]}')
        check(p['help'], f'{n}.{p["key"]}: no help')
        if p['type'] in ('int', 'float'):
            check(p['min'] <= p['max'], f'{n}.{p["key"]}: range [{p["min"]}, {p["max"]}]')
        if p['type'] == 'choice':
            check(p.get('choices') and all(isinstance(c, str) for c in p['choices']), f'{n}.{p["key"]}: choices {p.get("choices")}')
        for c in p.get('choices', []):
            check(valid(p, c), f'{n}.{p["key"]}: choice {c!r} outside its own declaration')
        if p['default'] is None:
            check(p.get('default_note'), f'{n}.{p["key"]}: a derived default without a note')
        else:
            check(valid(p, p['default']), f'{n}.{p["key"]}: default {p["default"]!r} outside its declaration')
    mp = m['main_parameter']
    if mp is not None:
        params = {p['key']: p for p in m['parameters']}
        check(mp['key'] in params, f'{n}: main parameter {mp["key"]} not declared')
        p = params.get(mp['key'])
        if p:
            check(all(valid(p, s) for s in mp['steps']), f'{n}: steps {mp["steps"]} not all valid')
            check(mp['default_step'] is not None and mp['steps'][mp['default_step']] == p['default'],
                  f'{n}: default_step {mp["default_step"]} of {mp["steps"]} is not the default {p["default"]}')
check(doc['common_parameters'][0]['key'] == 'device' and doc['common_parameters'][0]['default'] == 'cpu', f'common {doc["common_parameters"]}')

# by hand, from the code: pt.c, pm.c, ppm.c, vpolar.c, sdf/family.c
pt = {p['key']: p for p in methods['pt']['parameters']}
check(pt['spp']['default'] == 16 and pt['spp']['min'] == 1 and pt['spp']['max'] == 1 << 20, f'pt spp {pt["spp"]}')
check(pt['block_count']['default'] is None, f'pt block_count {pt["block_count"]}')
check(methods['pt']['devices'] == ['cpu', 'portable', 'cuda'], f'pt devices {methods["pt"]["devices"]}')
check(methods['pt']['main_parameter']['steps'] == [1, 2, 4, 8, 16, 32, 64] and methods['pt']['main_parameter']['progressive'],
      f'pt main {methods["pt"]["main_parameter"]}')
check(methods['fpm']['baseline'] == 'pm' and methods['fpm']['foveated'] and methods['fpm']['warmup_frames'] == 8, f'fpm {methods["fpm"]}')
ppm = {p['key']: p for p in methods['ppm']['parameters']}
check(abs(ppm['alpha']['default'] - 2 / 3) < 1e-15 and ppm['alpha']['min_open'] and ppm['alpha']['max_open'], f'ppm alpha {ppm["alpha"]}')
check(methods['vpolar']['baseline'] == 'cartesian-full' and methods['vpolar']['warmup_frames'] == 16, f'vpolar {methods["vpolar"]["baseline"]}')
check(methods['vpolar']['still_warmup_frames'] == 16 and methods['fir']['still_warmup_frames'] == 1 and methods['fpm']['still_warmup_frames'] == 0,
      'still warm-ups: vpolar 16 (SVGF), fir 1, fpm 0')
fipr = {p['key']: p for p in methods['fipr']['parameters']}
check(fipr['spp']['choices'] == [1, 4, 16] and fipr['refresh']['choices'] == [1, 2, 4], f'fipr spp {fipr["spp"]}, refresh {fipr["refresh"]}')
check(fipr['show']['choices'] == ['image', 'steps', 'level', 'mask', 'edges'] and fipr['show']['default'] == 'image', f'fipr show {fipr["show"]}')
sdfgt = {p['key']: p for p in methods['sdf-gt']['parameters']}
check(sdfgt['show']['choices'] == ['image', 'steps'], f'sdf-gt show {sdfgt["show"]}')

# NAME --json: that method's entry alone, in its family
for name in ('fpm', 'vpolar'):
    one = json.load(open(f'{tmp}/{name}.json'))
    check([m['name'] for m in one['methods']] == [name], f'methods {name} --json lists {[m["name"] for m in one["methods"]]}')
    check(one['methods'][0] == methods[name], f'methods {name} --json differs from its entry in the whole document')
    check(one['families'] == [{'name': methods[name]['family'], 'methods': [name]}], f'methods {name} --json families {one["families"]}')

# the text: the same methods (the first word of the lines that start with a letter), a family per
# heading; one method's text prints each of its parameters as key=...
listed = [l.split()[0] for l in open(f'{tmp}/list.txt') if l[:1].isalpha()]
grouped = [n for f in doc['families'] for n in f['methods']]
check(listed == grouped, f'fovea methods lists {listed}, the JSON {grouped}')
heads = [l[2:].strip() for l in open(f'{tmp}/list.txt') if l.startswith('# ')]
check(heads == [f['name'] for f in doc['families']], f'headings {heads}')
text = open(f'{tmp}/fipr.txt').read()
for p in methods['fipr']['parameters']:
    check(f'    {p["key"]}=' in text, f'fovea methods fipr does not print {p["key"]}')
check('refresh=1|2|4 (1): ' in text and 'relax=float (1) in [1, 2): ' in text, f'fovea methods fipr: {text}')
check('baseline        sdf-gt' in text, 'fovea methods fipr does not name its baseline')

for m in bad:
    print('FAIL:', m)
sys.exit(1 if bad else 0)
PY
finish
