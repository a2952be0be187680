#!/usr/bin/env bash
# report.html in a real browser: calibrate the committed golden session, open
# the report in Debian's headless Chromium, and require every plot rendered
# and no error on the page (the page collects errors into data-errors).
set -euo pipefail
bin="$1"; source_dir="$2"
scratch="$(mktemp -d)"; trap 'rm -rf "$scratch"' EXIT
cp -r "$source_dir/tests/golden/session" "$scratch/session"
"$bin/run-pipeline" "$scratch/session" >/dev/null 2>"$scratch/log" || { cat "$scratch/log"; exit 1; }
html="$scratch/session/calibrations/v0001/report.html"
[[ -s "$html" ]] || { echo "no report.html written"; cat "$scratch/log"; exit 1; }
# Offline: the page must not fetch anything.
if grep -Eq '<script[^>]*src=|<link[^>]*href="http' "$html"; then echo "report.html loads external assets"; exit 1; fi
dom="$(timeout 120 chromium --headless=new --no-sandbox --disable-gpu --disable-dev-shm-usage \
  --virtual-time-budget=20000 --dump-dom "file://$html" 2>"$scratch/chromium.log")"
body="$(grep -o '<body[^>]*>' <<<"$dom" | head -1)"
echo "$body"
grep -q 'data-status="ok"' <<<"$body" || { echo "page did not finish cleanly"; tail -20 "$scratch/chromium.log"; exit 1; }
plots="$(sed -E 's/.*data-plots="([0-9]+)".*/\1/' <<<"$body")"
[[ "$plots" == 10 ]] || { echo "expected 10 rendered plots, found $plots"; exit 1; }
grep -q 'data-errors=""' <<<"$body" || { echo "errors on the page"; exit 1; }
# One wall mask drawn for each planar snapshot the report keeps.
masks="$(sed -E 's/.*data-wall-masks="([0-9]+)".*/\1/' <<<"$body")"
snapshots="$(/usr/bin/python3 -c 'import json,sys; print(len(json.load(open(sys.argv[1]))["planar_snapshots"]))' \
  "$scratch/session/calibrations/v0001/report.json")"
[[ "$masks" == "$snapshots" && "$masks" -gt 0 ]] || { echo "expected $snapshots wall masks drawn, found $masks"; exit 1; }
echo "report.html: $plots plots rendered, $masks wall masks, no errors"
