#!/usr/bin/env bash
# The underwater preset's catalogue of scenes (docs/underwater.md): bakes each scene with the
# baker into OUT (default out/catalogue), one folder per scene, and prints its look (driven
# scenes) or its lean and flutter (still scenes in a current). About a minute.
# Usage: bash scripts/underwater_catalogue.sh [OUT] [INTEGRATOR]
# With INTEGRATOR (e.g. xpbd) every scene is baked with it at the automatic step (a fixed --dt
# below is dropped), to compare with the preset's own catalogue.
set -euo pipefail
cd "$(dirname "$0")/.."
OUT="${1:-out/catalogue}"
INTEGRATOR="${2:-}"
cargo build --release --quiet -p fraccloth-cli
BIN=target/release/fraccloth
bake() {  # name, then the baker's options
  local name="$1"; shift
  if [ -n "$INTEGRATOR" ]; then
    local kept=()
    while [ $# -gt 0 ]; do
      if [ "$1" = --dt ]; then shift 2; else kept+=("$1"); shift; fi
    done
    set -- "${kept[@]}" --integrator "$INTEGRATOR"
  fi
  "$BIN" --quiet --out "$OUT/$name" "$@" > "$OUT/$name.txt" 2>&1 || { echo "$name: refused"; tail -3 "$OUT/$name.txt"; return 0; }
  echo "== $name ($*)"
  grep -E "^(half-waves|travel|mid / bottom|zigzag|hang depth|streaming angle|flutter|look) " "$OUT/$name.txt" | sed 's/^/   /' || true
}
mkdir -p "$OUT"
for f in 0.25 0.5 1 2; do bake "swing-${f}hz" --frequency "$f"; done
bake swing-31x21 --size 31x21 --dt 0.001
bake swing-121x81 --size 121x81 --dt 0.00025
bake jittered --jittered
bake jittered-2hz --jittered --frequency 2
bake curtain-51x76 --scene curtain --dt 0.001
bake curtain-101x151 --scene curtain --size 101x151 --dt 0.0005
bake current-along --scene current --current 0.3,0,0
bake current-face-0.1 --scene current --current 0,0,0.1
bake current-face-0.3 --scene current --current 0,0,0.3
bake kelp-still --scene kelp --seconds 20
bake kelp-along-0.3 --scene kelp --current 0.3,0,0 --seconds 20
bake kelp-face-0.1 --scene kelp --current 0,0,0.1 --seconds 20
# Fast motion (stop 47): a pinned edge shaken at 2 m/s and a 2 m/s current face on bake (they
# were refused within the first frames before the water a stretched patch carries was bounded).
bake swing-2hz-16cm --frequency 2 --amplitude 0.16 --seconds 4
bake current-face-2 --scene current --current 0,0,2 --seconds 4
