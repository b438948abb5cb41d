#!/usr/bin/env bash
# Checks and times the wgpu modes on a machine with a real GPU, in one run.
#
#   scripts/gpu_check.sh ZOOVR GEN_MESH OUT
#
# ZOOVR and GEN_MESH are release builds of `zoovr` and of the `gen_mesh`
# example (`cargo build --release --bin zoovr --example gen_mesh`; build
# them on an x86-64 machine and copy them where the GPU machine has no
# Rust). OUT is a folder for the report: `gpu_check.txt` (what is printed)
# and `frames.jsonl` (every timed frame's `--stats --json` line).
# GRIDS="N1 N2" (environment) sets the grids' cell counts, default
# "1000000 5000000" (a smoke test here: GRIDS=8000).
#
# 1. The adapter: wgpu's choice, printed; a CPU rasteriser (llvmpipe,
#    lavapipe, SwiftShader) is named as such, since its numbers are not a
#    GPU's.
# 2. Correctness: every GPU mode against the ray caster on the project's
#    own meshes, two views each, `--split all` against `--model tets`, the
#    max over every pixel (`zoovr compare` on the float images). The modes'
#    bounds are in README ("Modes"): 2/255 for exact and exact-frag.
# 3. Throughput: warped hex grids of 1M and 5M cells, each GPU mode at
#    1024^2 and 2048^2 as a turntable of 4 frames (`zoovr animate --orbit 2
#    --count 4 --stats --json`). The first frame builds pipelines and the
#    order's structures; frames 1-3 are next frames (camera moved, so
#    re-sorted and re-projected). Per mode and size: the median next frame's
#    sort, draw (projection and GPU) and total seconds, and cells per second
#    (cells / total). Grids above 1M cells run exact-frag and preint3d
#    (both ways) only, to fit a 10-minute run.
# A mode written NAME:HOW is `--mode NAME --piece-draw HOW`: exact-frag and
# preint3d run both ways, their pieces projected into regions and drawn
# whole as quads (`--piece-draw auto` picks quads on a GPU; this checks that
# choice).
set -u
Z=${1:?zoovr binary}
G=${2:?gen_mesh binary}
OUT=${3:?output folder}
GRIDS=${GRIDS:-1000000 5000000}
mkdir -p "$OUT"
REPORT="$OUT/gpu_check.txt"
FRAMES="$OUT/frames.jsonl"
: >"$REPORT"
: >"$FRAMES"
say() { echo "$*" | tee -a "$REPORT"; }
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
HERE=$(cd "$(dirname "$0")/.." && pwd)

# 1. The adapter.
"$Z" render "$HERE/meshes/tetra.vtu" --size 64x64 -o "$WORK/a.png" --stats --json \
    >"$WORK/adapter.json" 2>"$WORK/adapter.err" || { say "render failed: $(tail -3 "$WORK/adapter.err")"; exit 1; }
ADAPTER=$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["gpu_adapter"])' "$WORK/adapter.json" 2>/dev/null \
    || grep -o '"gpu_adapter":"[^"]*"' "$WORK/adapter.json")
say "adapter: $ADAPTER"
case "$ADAPTER" in
*llvmpipe* | *lavapipe* | *SwiftShader* | *Cpu*) say "WARNING: a CPU rasteriser, not a GPU" ;;
esac

# The render flags of a mode NAME or NAME:HOW.
mode_args() {
    case "$1" in
    *:*) echo "--mode ${1%%:*} --piece-draw ${1#*:}" ;;
    *) echo "--mode $1" ;;
    esac
}

# 2. Correctness against the ray caster.
MODES="exact exact-frag:regions exact-frag:quads preint3d:regions preint3d:quads preint2d preint2d-cyl"
say ""
say "max error over every pixel, --split all against the ray caster on tets"
say "(bounds, each mode's registry entry: exact and exact-frag 7.8e-3 (2/255),"
say " preint3d and preint2d-cyl 4e-3, preint2d 6e-2 at the mean length):"
for mesh in zoo_3x3x3.vtu ring_hole.vtu curvilinear_4x4x4.vtu; do
    for view in "--azimuth 30 --elevation 20" "--azimuth 200 --elevation -40 --zoom 1.3 --ortho"; do
        # shellcheck disable=SC2086
        "$Z" render "$HERE/meshes/$mesh" $view --size 256x256 --mode raycast --model tets \
            --float "$WORK/ref.exr" -o "$WORK/ref.png" 2>/dev/null || { say "$mesh: reference failed"; continue; }
        line="$mesh [$view]:"
        for m in $MODES; do
            # shellcheck disable=SC2086
            if "$Z" render "$HERE/meshes/$mesh" $view --size 256x256 $(mode_args "$m") --split all \
                --float "$WORK/$m.exr" -o "$WORK/$m.png" 2>"$WORK/err"; then
                e=$("$Z" compare "$WORK/ref.exr" "$WORK/$m.exr" | awk '/max_abs/ {print $2}')
                line="$line $m $e"
            else
                line="$line $m FAILED($(tail -1 "$WORK/err"))"
            fi
        done
        say "$line"
    done
done

# 3. Throughput.
median() { sort -g | awk '{a[NR]=$1} END {if (NR) print a[int((NR+1)/2)]; else print "nan"}'; }
field() { python3 -c '
import json, sys
key = sys.argv[1]
for line in sys.stdin:
    d = json.loads(line)
    if d.get("frame", 0) >= 1:
        print(d[key] if key in d else d["render"][key])
' "$1"; }
run_grid() {
    local hexes=$1 modes=$2
    local mesh="$WORK/hex_$hexes.vtu"
    say ""
    local t0=$SECONDS
    "$G" --hexes "$hexes" -o "$mesh" --raw >/dev/null 2>&1 || { say "gen_mesh --hexes $hexes failed"; return; }
    local cells
    cells=$("$Z" info "$mesh" --json | python3 -c 'import json,sys; print(json.load(sys.stdin)["cells3d"])')
    say "grid: $cells hexes (written in $((SECONDS - t0)) s)"
    say "mode                size   sort s   draw s   total s   cells/s (median of frames 1-3)"
    for size in 1024 2048; do
        for m in $modes; do
            rm -rf "$WORK/frames"
            # shellcheck disable=SC2046
            if ! timeout 240 "$Z" animate "$mesh" --orbit 2 --count 4 $(mode_args "$m") --size "${size}x$size" \
                --azimuth 20 --elevation 35 -o "$WORK/frames" --stats --json >"$WORK/f.jsonl" 2>"$WORK/err"; then
                say "$m $size: FAILED ($(tail -1 "$WORK/err"))"
                continue
            fi
            sed "s/^/{\"grid\":$cells,\"size\":$size,\"row\":/; s/\$/}/" "$WORK/f.jsonl" >>"$FRAMES"
            local s d t
            s=$(field sort_s <"$WORK/f.jsonl" | median)
            d=$(field draw_s <"$WORK/f.jsonl" | median)
            t=$(field total_s <"$WORK/f.jsonl" | median)
            say "$(printf '%-19s %-6s %-8.3f %-8.3f %-9.3f %.3g' "$m" "$size" "$s" "$d" "$t" "$(echo "$cells / $t" | bc -l)")"
        done
    done
    rm -f "$mesh"
}
for n in $GRIDS; do
    if [ "$n" -gt 1000000 ]; then
        run_grid "$n" "exact-frag:regions exact-frag:quads preint3d:regions preint3d:quads"
    else
        run_grid "$n" "$MODES"
    fi
done
