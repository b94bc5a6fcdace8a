#!/usr/bin/env bash
# Refreshes the guide's and the README's pictures with orthosim's own `screenshot` command, in a
# real window under Xvfb with Mesa's software drivers (Debian packages xvfb, mesa-vulkan-drivers).
# Run from anywhere: `bash docs/images/make.sh`. Set ORTHOSIM to use a built binary.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
root="$(cd "$here/../.." && pwd)"
if [ -z "${ORTHOSIM:-}" ]; then
    (cd "$root" && cargo build --release --quiet)
    ORTHOSIM="${CARGO_TARGET_DIR:-$root/target}/release/orthosim"
fi
if ! command -v xvfb-run >/dev/null; then
    echo "make.sh: xvfb-run is not installed (Debian packages xvfb, mesa-vulkan-drivers)" >&2
    exit 1
fi
shot() {
    local out="$1"
    shift
    echo "$out"
    local log
    log="$(mktemp)"
    if ! xvfb-run -a -s "-screen 0 1280x800x24" "$ORTHOSIM" screenshot --out "$here/$out" "$@" \
        > "$log" 2>&1; then
        cat "$log" >&2
        rm -f "$log"
        exit 1
    fi
    rm -f "$log"
}
# The viewer: the panel, the teeth window and the occlusal contact map of the normal bite's
# lower arch (red in contact, through yellow and green, to blue at 0.5 mm).
shot viewer.png --case normal --view mandibular --hide upper --panel --overlay occlusion-map \
    --frames 60
# A plan half-way: the crowded lower arch from above, each tooth coloured by what it still has
# to move.
shot plan.png --case crowded --view mandibular --hide upper --plan 5 --frames 30
# A target being edited: 33's handles and its gaps to its neighbours.
shot edit-target.png --case crowded --view left --plan 999 --select 33 --edit-target --frames 30
# The paper's case 1 from the right under the exact stage, its contacts marked (Figure 6).
shot contacts.png --case case1 --view right --algorithm exact --overlay contacts --frames 120
