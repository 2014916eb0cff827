#!/usr/bin/env bash
# The wheel as a user gets it: built from a copy of the sources, installed with its
# dependencies (the versions of constraints.txt) into a fresh venv
# outside the repository, then run from there: --version, no display -> exit 2, a headless
# 2D render of the bundled demo to a GIF, and the data files (shaders, scenes, docs, desktop
# files, LICENSE) present in the installed package.
#
# The dependency wheels are kept in .venv/wheelhouse (ignored by git): the first run fills it
# with `pip download`, later runs install from it without the network.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
cd "$repo"
python="${PYTHON:-python3}"
work="$(mktemp -d "${TMPDIR:-/tmp}/qtanimator-wheel-check.XXXXXX")"
trap 'rm -rf "$work"' EXIT
say() { echo "wheel_check: $*"; }

# 1. Build from a copy, so that the checkout gets no build/ or egg-info.
mkdir -p "$work/src"
cp -r qtanimator resources scenes docs pyproject.toml setup.py README.md LICENSE "$work/src/"
find "$work/src" -name __pycache__ -prune -exec rm -rf {} +
.venv/bin/python -m pip wheel "$work/src" --no-deps --no-build-isolation --no-index -q -w "$work/dist"
wheel="$(ls "$work"/dist/qtanimator-*.whl)"
say "built $(basename "$wheel")"

# 2. A fresh venv, outside the repository, with the runtime dependencies at the tested versions.
wheelhouse="$repo/.venv/wheelhouse"
"$python" -m venv "$work/venv"
pip=("$work/venv/bin/python" -m pip --disable-pip-version-check)
if ! "${pip[@]}" install -q --no-index --find-links "$wheelhouse" -c constraints.txt "$wheel" 2>/dev/null; then
  say "filling $wheelhouse (first run)"
  mkdir -p "$wheelhouse"
  "${pip[@]}" download -q -d "$wheelhouse" -c constraints.txt "$wheel"
  "${pip[@]}" install -q --no-index --find-links "$wheelhouse" -c constraints.txt "$wheel"
fi
say "installed into a fresh venv"

# 3. Run it from outside the repository.
cd "$work"
exe="$work/venv/bin/qtanimator"
"$exe" --version | grep -qx "qtanimator $(cd "$repo" && .venv/bin/python -c 'import qtanimator; print(qtanimator.__version__)')"
set +e
env -u DISPLAY -u WAYLAND_DISPLAY -u QT_QPA_PLATFORM XDG_STATE_HOME="$work/state" "$exe" 2>"$work/nodisplay.txt"
status=$?
set -e
test "$status" = 2 && grep -q "no display: run under a desktop session" "$work/nodisplay.txt" \
  && test "$(wc -l <"$work/nodisplay.txt")" = 1 || { say "no display: exit $status"; cat "$work/nodisplay.txt"; exit 1; }
demo="$("$work/venv/bin/python" -c 'from qtanimator.paths import demo_project; print(demo_project())')"
case "$demo" in "$work/venv/"*) ;; *) say "the demo is not the installed one: $demo"; exit 1 ;; esac
env -u DISPLAY -u WAYLAND_DISPLAY QT_QPA_PLATFORM=offscreen \
  "$exe" render "$demo" -o "$work/demo.gif" --frames 0:12 --size 240x160 --quiet
"$work/venv/bin/python" - "$work/demo.gif" <<'PY'
import sys
from importlib import metadata
from importlib.util import find_spec
from pathlib import Path

from PIL import Image

import qtanimator
from qtanimator import paths

gif = Image.open(sys.argv[1])
# 13 frames of the 60 fps demo: a GIF holds at most 50 fps (2 cs delays), so one frame in six is
# dropped evenly and the duration kept (issue 15): 11 frames, 13/60 s in all.
durations = []
for i in range(gif.n_frames):
    gif.seek(i)
    durations.append(gif.info["duration"])
assert gif.format == "GIF" and gif.size == (240, 160) and gif.n_frames == 11, (gif.format, gif.size, gif.n_frames)
assert min(durations) >= 20 and abs(sum(durations) - 1000 * 13 / 60) <= 10, durations
package = Path(qtanimator.__file__).resolve().parent
assert "site-packages" in package.parts, package
for path in (paths.shader_path("mesh.vert"), paths.app_icon_path(), paths.demo_project(),
             paths.desktop_dir() / f"{paths.APP_ID}.desktop", paths.desktop_dir() / f"{paths.APP_ID}.metainfo.xml",
             paths.desktop_dir() / f"{paths.APP_ID}.mime.xml", paths.docs_dir() / "user-guide.md",
             paths.docs_dir() / "keyboard.md", paths.docs_dir() / "images" / "main_window.png"):
    assert path.is_file() and package in path.parents, path
dist = metadata.distribution("qtanimator")
assert dist.metadata["License-Expression"] == "MIT"
assert any(str(f).endswith("licenses/LICENSE") for f in dist.files or []), "no LICENSE in the dist-info"
from qtanimator.core import cloth_kernels
from qtanimator.core.cloth import Cloth

# numba is a dependency (issue 30): a plain install runs the compiled cloth.
assert find_spec("numba") is not None and cloth_kernels.HAVE_NUMBA and Cloth().accelerated, "no compiled cloth"
print("wheel_check: GIF of 11 frames (13 at 60 fps), data files, LICENSE present; the compiled cloth kernels")
PY
say "ok"
