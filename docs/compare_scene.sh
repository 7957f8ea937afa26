# Sourced by docs/compare_all.sh and docs/converge_single.sh: one scene against Mitsuba 3.
# compare_scene OUT SCENE NAME MITSUBA_SPP SPP SHADING_POINTS METHOD...
#   renders the Mitsuba reference (with its standard error and coverage) once into
#   OUT/NAME_mts.exr, then each METHOD with `ppis render` (binary: $PPIS, default
#   ./target/release/ppis) into OUT/NAME_METHOD.exr, and prints docs/compare_mitsuba.py's figures.
compare_scene() {
    local out="$1" scene="$2" name="$3" mts_spp="$4" spp="$5" points="$6"
    shift 6
    if [ ! -f "$out/${name}_mts.exr" ]; then
        python3 docs/reference/mitsuba_ref.py "$scene" --spp "$mts_spp" --passes 4 \
            --out "$out/${name}_mts.exr" --stderr-out "$out/${name}_mts_se.exr" \
            --coverage-out "$out/${name}_cov.exr" | tail -1
    fi
    local m
    for m in "$@"; do
        "${PPIS:-./target/release/ppis}" render "$scene" --method "$m" --spp "$spp" \
            --shading-points "$points" -o "$out/${name}_$m.exr" 2>&1 | tail -1 | sed 's/; wrote.*//'
        printf '%s %s: ' "$name" "$m"
        python3 docs/compare_mitsuba.py "$out/${name}_$m.exr" "$out/${name}_mts.exr" \
            "$out/${name}_cov.exr" "$out/${name}_mts_se.exr" | tr '\n' ' '
        echo
    done
}
