#!/bin/bash
# Every bundled scene's evaluation, into benches/evaluation/<scene>/, then docs/MEASURED.md's
# fronts table from the new reports. From the repository root, after `cargo build --release`:
#
#   benches/evaluate_all.sh [BINARY] [-- EVALUATE OPTIONS]
#
# defaults: target/release/shadowgraph, `--sizes 512 --repeat 3`. On a CPU driver (lavapipe)
# run it on an idle machine: a load that changes within a frame moves the times by more than
# the spread the report prints, and the fronts with them (docs/EVALUATION.md). The load
# average is printed before and after each scene, so that a loaded run shows. SCENES="a b"
# picks scenes.
set -u
B=${1:-target/release/shadowgraph}
shift || true
[ "${1:-}" = "--" ] && shift
OPTS=("$@")
[ ${#OPTS[@]} -eq 0 ] && OPTS=(--sizes 512 --repeat 3)
LOGS=$(mktemp -d)
SCENES=${SCENES:-"bunny casters_on_plane city city_street colonnade colonnade_sun forest grazing grazing_solid long_shadows moving_object point pole sphere_on_plane stacked two_lights"}
for s in $SCENES; do
    start=$(date +%s)
    echo "$s: load $(cut -d' ' -f1-3 /proc/loadavg)"
    "$B" evaluate "scenes/$s.toml" "${OPTS[@]}" --out "benches/evaluation/$s" >"$LOGS/$s.log" 2>&1 ||
        { echo "$s failed:"; tail -5 "$LOGS/$s.log"; }
    echo "$s: $(($(date +%s) - start)) s, load $(cut -d' ' -f1-3 /proc/loadavg)"
done
SHADOWGRAPH_BLESS=1 cargo test --release --test readme_fronts
