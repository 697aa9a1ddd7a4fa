# docs/results.md is a results document a reader can trust (issue 27): every table has, between its
# heading and itself, a *Measured:* paragraph naming the commit, the machine and the command, and
# superseded figures live in the History section, which stays last. scripts/check-results-doc
# checks both; here it runs on the real document and on small documents that must fail.
. "$(dirname "$0")/lib.sh"
CHECK=$SRC/scripts/check-results-doc

expect 0 "" -- python3 "$CHECK" "$SRC/docs/results.md"

good='*Measured:* commit 1a2b3c4 (2026-11-27). Machine: 2-core Debian 12 VM, shared.
*Command:* `fovea bench x`.'
table='| a | b |
|---|---:|
| x | 1 |'
history='## History: superseded figures'

# write NAME BODY: a document with one section holding BODY, then the History section.
write() { printf '# Results\n\n## A\n\n%s\n\n%s\n' "$2" "$history" >"$TMP/$1.md"; }

write ok "$good

$table"
expect 0 "" -- python3 "$CHECK" "$TMP/ok.md"

# A table with no provenance at all, named by its line (7: after the title, heading and text).
write bare "Some text.

$table"
expect 1 "bare.md:7: table without provenance: no *Measured:*" -- python3 "$CHECK" "$TMP/bare.md"

# Each of the three items missing in turn.
write nocommit "${good/commit 1a2b3c4/the latest build}

$table"
expect 1 "lacks a commit" -- python3 "$CHECK" "$TMP/nocommit.md"
write nomachine "${good/Machine:/On a}

$table"
expect 1 "lacks the machine" -- python3 "$CHECK" "$TMP/nomachine.md"
write nocommand "${good/\*Command:\*/Run}

$table"
expect 1 "lacks the command" -- python3 "$CHECK" "$TMP/nocommand.md"

# Provenance in another section does not cover a table under a later heading.
write othersection "$good

### B

$table"
expect 1 "table without provenance" -- python3 "$CHECK" "$TMP/othersection.md"

# A table inside a code fence is text; a |---| line alone is not a table's start.
write fenced '```
| a | b |
|---|---|
```'
expect 0 "" -- python3 "$CHECK" "$TMP/fenced.md"

# History must stay the last section.
printf '# Results\n\n%s\n\n## Later\n\nText.\n' "$history" >"$TMP/order.md"
expect 1 "the last section must be" -- python3 "$CHECK" "$TMP/order.md"

expect 2 "cannot read" -- python3 "$CHECK" "$TMP/absent.md"
finish
