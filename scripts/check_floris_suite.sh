#!/usr/bin/env bash
# check_floris_suite.sh - does importing floris_ekman_veer change the outcome of FLORIS's own tests?
#
# Project rule: FLORIS's test suite must give the same results with this package imported (models
# registered, inflow hook installed) as without it. This script runs the suite twice against the
# FLORIS installed in the chosen Python environment and compares the outcome of every test:
#
#   pass A  plain FLORIS
#   pass B  the same, with `import floris_ekman_veer` done by a pytest plugin before collection
#
# Usage:
#   scripts/check_floris_suite.sh TESTS_DIR [PYTEST_ARGS...]
#
#   TESTS_DIR    the tests/ directory of a FLORIS source checkout (FLORIS's tests are not in its
#                sdist/wheel), e.g. from a git mirror without work tree:
#                  mkdir -p /tmp/floris_src
#                  git -C <floris.git> archive <tag> tests | tar -x -C /tmp/floris_src
#                  scripts/check_floris_suite.sh /tmp/floris_src/tests
#                Use the tag closest to the installed FLORIS. Tests from another release may fail
#                against the installed FLORIS; that is fine as long as they fail in both passes.
#   PYTEST_ARGS  passed to both pytest runs (e.g. -k par_floris, --deselect ID, --durations=10).
#
# Environment:
#   PYTHON          interpreter whose site-packages hold floris and pytest (default: python3).
#                   Its bin directory is put first on PATH (some FLORIS tests run `python`).
#   FEV_ROOT        source root of floris_ekman_veer (default: the repository holding this script).
#   FEV_OUT         directory for logs, junit XML and the copies of the tests (default: mktemp -d).
#                   Kept after the run; its path is printed.
#   FEV_PYTHON_FILES  pytest python_files patterns (default also collects FLORIS's test files that
#                   pytest's default patterns miss, e.g. wake_unit_tests.py,
#                   reg_tests/scipy_layout_opt_regression.py). Set it to
#                   "test_*.py *_test.py" to collect exactly what FLORIS's own CI collects.
#
# Each pass runs on a fresh copy of TESTS_DIR (named tests/, because FLORIS's tests import
# tests.conftest), in a directory that contains no `floris` package, so the installed FLORIS is
# the one tested and the checkout is never written to. Pass A asserts that floris_ekman_veer was
# never imported; pass B asserts that the hook was installed for the whole session.
#
# Exit status: 0 same outcomes; 1 some test's outcome differs (listed, with its pass-B report);
#              2 usage or setup error (pytest crashed, no tests collected, plugin not active, ...).
# Tests that fail in both passes with different messages are listed for information only.
# Flaky tests show up as differences: rerun just them with PYTEST_ARGS to confirm.

set -euo pipefail

usage() { awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"; }

if [[ $# -lt 1 || "$1" == "-h" || "$1" == "--help" ]]; then
    usage
    [[ $# -ge 1 ]] && exit 0 || exit 2
fi

TESTS_DIR=$(cd "$1" 2>/dev/null && pwd) || { echo "error: no such directory: $1" >&2; exit 2; }
shift
[[ -f "$TESTS_DIR/conftest.py" ]] || {
    echo "error: $TESTS_DIR has no conftest.py; give FLORIS's tests/ directory" >&2; exit 2; }

SCRIPT_DIR=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
FEV_ROOT=$(cd "${FEV_ROOT:-$SCRIPT_DIR/..}" && pwd)
PYTHON=${PYTHON:-python3}
PYTHON=$(command -v "$PYTHON") || { echo "error: no interpreter ${PYTHON}" >&2; exit 2; }
PY_BIN=$("$PYTHON" -c 'import os, sys; print(os.path.dirname(sys.executable))')
FEV_OUT=${FEV_OUT:-$(mktemp -d "${TMPDIR:-/tmp}/fev_floris_suite.XXXXXX")}
mkdir -p "$FEV_OUT"
FEV_OUT=$(cd "$FEV_OUT" && pwd)
FEV_PYTHON_FILES=${FEV_PYTHON_FILES:-"test_*.py *_test.py *_tests.py *_regression.py"}

[[ -d "$FEV_ROOT/floris_ekman_veer" ]] || {
    echo "error: FEV_ROOT=$FEV_ROOT does not contain floris_ekman_veer/" >&2; exit 2; }
"$PYTHON" -c 'import floris, pytest' 2>/dev/null || {
    echo "error: $PYTHON cannot import floris and pytest" >&2; exit 2; }

# The pytest plugin: pass B imports the package before collection; both passes record, at the end
# of the session, whether the package was imported and whether the hook was installed.
PLUGIN_DIR="$FEV_OUT/plugin"
mkdir -p "$PLUGIN_DIR"
cat > "$PLUGIN_DIR/fev_suite_plugin.py" <<'EOF'
"""pytest plugin of check_floris_suite.sh (FEV_SUITE_MODE=plain|package, FEV_SUITE_STATE=file)."""
import json
import os
import sys

MODE = os.environ["FEV_SUITE_MODE"]

if MODE == "package":
    import floris_ekman_veer  # noqa: F401  (registers the models, installs the inflow hook)


def _state():
    state = {"mode": MODE, "imported": "floris_ekman_veer" in sys.modules, "installed": False}
    if state["imported"]:
        from floris_ekman_veer.plugin.floris_hooks import patching

        state["installed"] = patching.is_installed()
        state["patched"] = sorted(f"{owner.__name__}.{name}" for owner, name in patching.ORIGINALS)
        state["package"] = sys.modules["floris_ekman_veer"].__file__
    return state


def pytest_report_header(config):
    import floris

    return f"fev_suite_plugin: mode={MODE} floris={floris.__version__} state={_state()}"


def pytest_sessionfinish(session, exitstatus):
    with open(os.environ["FEV_SUITE_STATE"], "w") as handle:
        json.dump(_state(), handle)
EOF

FLORIS_VERSION=$("$PYTHON" -c 'import floris; print(floris.__version__)')
TESTS_REV=$(git -C "$TESTS_DIR" describe --tags --always 2>/dev/null || echo "unknown (not a git work tree)")
echo "FLORIS installed: $FLORIS_VERSION ($PYTHON)"
echo "FLORIS tests:     $TESTS_DIR (revision: $TESTS_REV)"
echo "package:          $FEV_ROOT"
echo "output:           $FEV_OUT"

run_pass() {  # run_pass NAME MODE [PYTEST_ARGS...]
    local name=$1 mode=$2 rc start end
    shift 2
    rm -rf "${FEV_OUT:?}/$name"
    mkdir -p "$FEV_OUT/$name"
    cp -R "$TESTS_DIR" "$FEV_OUT/$name/tests"
    local pythonpath="$PLUGIN_DIR"
    [[ "$mode" == package ]] && pythonpath="$pythonpath:$FEV_ROOT"
    echo "pass $name ($mode): running..."
    start=$(date +%s)
    set +e
    (
        cd "$FEV_OUT/$name" &&
        PATH="$PY_BIN:$PATH" PYTHONPATH="$pythonpath${PYTHONPATH:+:$PYTHONPATH}" \
        FEV_SUITE_MODE=$mode FEV_SUITE_STATE="$FEV_OUT/$name.state.json" \
        "$PYTHON" -m pytest tests -q -rA -p no:cacheprovider -p fev_suite_plugin \
            -o "python_files=$FEV_PYTHON_FILES" --junitxml="$FEV_OUT/$name.xml" "$@"
    ) > "$FEV_OUT/$name.log" 2>&1
    rc=$?
    set -e
    end=$(date +%s)
    echo "$((end - start))" > "$FEV_OUT/$name.seconds"
    echo "pass $name ($mode): pytest exit $rc, $((end - start)) s wall, log $FEV_OUT/$name.log"
    if [[ $rc -ne 0 && $rc -ne 1 ]]; then
        echo "error: pytest exit status $rc in pass $name (not a plain test failure):" >&2
        tail -n 30 "$FEV_OUT/$name.log" >&2
        exit 2
    fi
}

run_pass A plain "$@"
run_pass B package "$@"

"$PYTHON" - "$FEV_OUT" <<'EOF'
import json
import re
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

out = Path(sys.argv[1])
OUTCOMES = ("passed", "failed", "error", "skipped")


def check_state(name, want_imported):
    state = json.loads((out / f"{name}.state.json").read_text())
    if state["imported"] != want_imported or (want_imported and not state["installed"]):
        sys.exit(f"error: pass {name}: unexpected package state {state}")
    return state


def load(name):
    """{test id: (outcome, message, text)}; if a test has several reports, the worst wins."""
    severity = {"passed": 0, "skipped": 1, "failed": 2, "error": 3}
    results = {}
    root = ET.parse(out / f"{name}.xml").getroot()
    for case in root.iter("testcase"):
        classname, test = case.get("classname", ""), case.get("name", "")
        test_id = f"{classname}::{test}" if classname else test
        for child in list(case) or [None]:
            tag = {"failure": "failed", "error": "error", "skipped": "skipped"}.get(
                getattr(child, "tag", None), "passed")
            report = (tag, child.get("message", "") if tag != "passed" else "",
                      (child.text or "") if tag != "passed" else "")
            if test_id not in results or severity[tag] > severity[results[test_id][0]]:
                results[test_id] = report
    if not results:
        sys.exit(f"error: pass {name} recorded no tests")
    return results


def normalise(message):
    """Drop what differs between passes anyway: object addresses, each pass's copy of tests/."""
    for name in ("A", "B"):
        message = message.replace(str(out / name), "<pass>")
    return re.sub(r"0x[0-9a-fA-F]+", "0x?", message).strip()


check_state("A", False)
state_b = check_state("B", True)
a, b = load("A"), load("B")
print()
print(f"patched in pass B: {', '.join(state_b.get('patched', []))}")
for name, results in (("A plain", a), ("B with floris_ekman_veer", b)):
    counts = {o: sum(r[0] == o for r in results.values()) for o in OUTCOMES}
    seconds = (out / f"{name[0]}.seconds").read_text().strip()
    print(f"pass {name}: {len(results)} tests, "
          + ", ".join(f"{counts[o]} {o}" for o in OUTCOMES) + f"; {seconds} s wall")

differences = []
for test_id in sorted(set(a) | set(b)):
    oa = a.get(test_id, ("absent",))[0]
    ob = b.get(test_id, ("absent",))[0]
    if oa != ob:
        differences.append((test_id, oa, ob))
message_changes = [
    t for t in sorted(set(a) & set(b))
    if a[t][0] == b[t][0] != "passed" and normalise(a[t][1]) != normalise(b[t][1])
]

if message_changes:
    print(f"\n{len(message_changes)} test(s) with the same outcome but a different message "
          "(information only):")
    for t in message_changes:
        print(f"  {t}\n    A: {a[t][1][:300]}\n    B: {b[t][1][:300]}")

if not differences:
    print("\nOK: every test has the same outcome with and without floris_ekman_veer.")
    sys.exit(0)

print(f"\nFAIL: {len(differences)} test(s) differ (outcome A -> B):")
for test_id, oa, ob in differences:
    print(f"  {test_id}: {oa} -> {ob}")
for test_id, oa, ob in differences:
    report = b.get(test_id)
    if report and report[0] in ("failed", "error"):
        print(f"\n---- pass B report of {test_id} ----\n{report[2].rstrip()}")
sys.exit(1)
EOF
