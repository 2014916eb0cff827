#!/usr/bin/env bash
# The whole test suite against the wheel as a user's pip installs it, with one dependency set:
#
#   .ci/suite_with.sh newest   no constraints: the newest releases pyproject.toml allows
#   .ci/suite_with.sh oldest   constraints-min.txt: the oldest releases it claims
#   (the pinned set, constraints.txt, is ./dev.sh test's)
#   .ci/suite_with.sh SET --prepare   only build and install (CI does this while other tests run)
#
# The wheel is built from a copy of the sources and installed with its [test] extra into
# .ci-venvs/<set> (ignored by git; kept between runs, reinstalled when the sources or the
# constraints change). The tests then import the installed qtanimator, not the checkout: pytest
# is run as a script (`python -m pytest` would put the checkout first on sys.path). The log
# shows the versions the job ran with. Extra arguments go to pytest.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
cd "$repo"
set_name="${1:?usage: .ci/suite_with.sh newest|oldest [PYTEST ARGS]}"
shift
case "$set_name" in
  newest) constraints=() ;;
  oldest) constraints=(-c constraints-min.txt) ;;
  *) echo "suite_with.sh: unknown set $set_name (newest or oldest)" >&2; exit 2 ;;
esac
python="${PYTHON:-python3}"
venv="$repo/.ci-venvs/$set_name"
say() { echo "suite_with[$set_name]: $*"; }

work="$(mktemp -d "${TMPDIR:-/tmp}/qtanimator-suite-$set_name.XXXXXX")"
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/src"
cp -r qtanimator resources scenes docs pyproject.toml setup.py README.md LICENSE "$work/src/"
find "$work/src" -name __pycache__ -prune -exec rm -rf {} +
# Reinstalled when what pip resolves changes (the metadata or the constraints); only the wheel
# when just the sources changed.
deps="$(cat pyproject.toml setup.py constraints.txt constraints-min.txt | sha1sum | cut -d' ' -f1)"
sources="$(cd "$work/src" && find . -type f -print0 | sort -z | xargs -0 sha1sum | sha1sum | cut -d' ' -f1)"
build_wheel() {
  "$venv/bin/python" -m pip wheel -q "$work/src" --no-deps --no-build-isolation -w "$work/dist"
  ls "$work"/dist/qtanimator-*.whl
}
if [ ! -f "$venv/.deps" ] || [ "$(cat "$venv/.deps")" != "$deps" ]; then
  rm -rf "$venv"
  "$python" -m venv "$venv"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check --upgrade pip setuptools wheel
  wheel="$(build_wheel)"
  say "installing $(basename "$wheel")[test] ${constraints[*]:-(no constraints: the newest allowed)}"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check "${wheel}[test]" "${constraints[@]}"
  echo "$deps" >"$venv/.deps"
  echo "$sources" >"$venv/.sources"
elif [ ! -f "$venv/.sources" ] || [ "$(cat "$venv/.sources")" != "$sources" ]; then
  wheel="$(build_wheel)"
  say "reinstalling $(basename "$wheel") (the sources changed)"
  "$venv/bin/python" -m pip install -q --disable-pip-version-check --no-deps --force-reinstall "$wheel"
  echo "$sources" >"$venv/.sources"
fi
versions="$("$venv/bin/python" -c '
import sys
from importlib import metadata
names = ["PySide6-Essentials", "shiboken6", "numpy", "scipy", "numba", "pyqtgraph", "PyOpenGL", "svgelements",
         "imageio", "imageio-ffmpeg", "pillow", "tqdm", "pytest", "pytest-qt"]
print(f"Python {sys.version.split()[0]}; " + ", ".join(f"{n} {metadata.version(n)}" for n in names))
')"
say "versions: $versions"
if [ "${1:-}" = "--prepare" ]; then exit 0; fi
# The tests must see the installed package, not the checkout.
where="$(cd "$work" && "$venv/bin/python" -c 'import qtanimator; print(qtanimator.__file__)')"
case "$where" in "$venv/"*) ;; *) say "qtanimator imports from $where, not the venv"; exit 1 ;; esac
exec "$venv/bin/pytest" -p no:cacheprovider "$@"
