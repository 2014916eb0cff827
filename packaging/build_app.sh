#!/usr/bin/env bash
# Build the one-folder app with PyInstaller and check it headless.
#   packaging/build_app.sh [DISTDIR]      (default: dist/; work folder: $WORKPATH or build/pyinstaller)
# Needs the package extra: .venv/bin/pip install -e ".[package]" -c constraints.txt
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
dist="${1:-$root/dist}"
py="${PYTHON:-$root/.venv/bin/python}"
"$py" -m PyInstaller --noconfirm --clean --distpath "$dist" --workpath "${WORKPATH:-$root/build/pyinstaller}" \
  packaging/qtanimator.spec
app="$dist/qtanimator/qtanimator"
# The desktop integration installer goes beside the executable (it finds the bundle's files).
install -m755 packaging/install-desktop-integration.sh "$dist/qtanimator/install-desktop-integration.sh"
"$app" --version
"$app" info "$dist/qtanimator/_internal/qtanimator/scenes/flappy.svg" >/dev/null
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
# A 2D render needs no display: Qt's offscreen platform.
env -u DISPLAY -u WAYLAND_DISPLAY QT_QPA_PLATFORM=offscreen \
  "$app" render "$dist/qtanimator/_internal/qtanimator/scenes/flappy_hop.qtanim" -o "$out/flappy.gif" \
  --frames 0:30 --size 320x360 --quiet
test -s "$out/flappy.gif"
"$app" render "$dist/qtanimator/_internal/qtanimator/scenes/robot/robot.qtanim" -o "$out/robot.mp4" \
  --frames 0:30 --size 320x240 --quiet
test -s "$out/robot.mp4"
"$dist/qtanimator/install-desktop-integration.sh" --prefix "$out/share" >/dev/null
grep -q "^Exec=\"$dist/qtanimator/qtanimator\" %f" "$out/share/applications/io.github.qtanimator.qtanimator.desktop"
test -s "$out/share/icons/hicolor/scalable/apps/io.github.qtanimator.qtanimator.svg"
test -s "$out/share/metainfo/io.github.qtanimator.qtanimator.metainfo.xml"
test -s "$out/share/mime/packages/io.github.qtanimator.qtanimator.xml"
echo "build_app.sh: $app works (version, info, GIF and MP4 render, desktop integration)"
