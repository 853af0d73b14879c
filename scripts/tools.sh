# Set-up shared by validate.sh and race.sh, sourced from the repository root once OUT is set:
# LF (the lfgen binary, built unless given), lf (runs it inside $OUT, so the built-in defaults
# apply whatever ./generator.toml holds), PY (a Python venv with Mitsuba, numpy and OpenEXR,
# made at $VENV, default $OUT/venv) and VAL (validate.py).
if [ -z "${LF:-}" ]; then
    cargo build --release --quiet
    LF=$(realpath target/release/lfgen)
fi
mkdir -p "$OUT"
lf() { (cd "$OUT" && "$LF" "$@"); }
VENV=$(realpath -m "${VENV:-$OUT/venv}")
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
    "$VENV/bin/pip" install --quiet mitsuba numpy OpenEXR
fi
PY="$VENV/bin/python"
VAL="$(pwd)/scripts/validate.py"
