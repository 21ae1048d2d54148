#!/usr/bin/env bash
# Screenshots of the built site at 1280 px in headless Chromium (Debian's `chromium`
# package), written to docs/img/site/. Run from the repository root:
#   bash docs/screenshots.sh
set -euo pipefail
out=docs/img/site
site=$(mktemp -d)
mkdocs build --strict -q -d "$site"
port=8765
python -m http.server "$port" --bind 127.0.0.1 --directory "$site" >/dev/null 2>&1 &
server=$!
trap 'kill $server; rm -rf "$site"' EXIT
sleep 1
shot() {  # shot NAME PATH
  chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run \
    --disable-background-networking --disable-component-update --disable-sync \
    --user-data-dir="$(mktemp -d)" --hide-scrollbars --window-size=1280,1000 \
    --screenshot="$out/$1.png" "http://127.0.0.1:$port/$2" 2>/dev/null
}
shot index ""
shot tutorial tutorial-aimapp/
shot api api/inference/
shot exploration exploration/
shot results-table results/drift-full/table/
shot environments environments/
