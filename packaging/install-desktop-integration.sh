#!/usr/bin/env bash
# Install qtanimator's desktop integration for the current user (or under a prefix): the
# .desktop entry, the icon, the AppStream metainfo and the MIME type of *.qtanim projects.
#
#   ./install-desktop-integration.sh [--prefix DIR] [--exec PATH] [--uninstall]
#
# Beside the one-folder PyInstaller app (dist/qtanimator/, where build_app.sh copies this
# script) it takes the files from the bundle (_internal/qtanimator/resources/desktop) and
# points the menu entry at the bundle's executable. From a checkout or with a pip-installed
# qtanimator it takes resources/desktop and the `qtanimator` found on PATH (or --exec), written
# as an absolute path: a desktop session's PATH rarely holds a venv's or pipx's bin folder, and
# an entry whose command is not found is hidden.
# DIR defaults to $XDG_DATA_HOME (~/.local/share); use --prefix /usr/local/share as root.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
app_id="io.github.qtanimator.qtanimator"
prefix="${XDG_DATA_HOME:-$HOME/.local/share}"
exec_path=""
uninstall=0
while [ $# -gt 0 ]; do
  case "$1" in
    --prefix) prefix="$2"; shift 2 ;;
    --exec) exec_path="$2"; shift 2 ;;
    --uninstall) uninstall=1; shift ;;
    -h|--help) sed -n '2,12p' "$0"; exit 0 ;;
    *) echo "install-desktop-integration.sh: unknown argument $1 (try --help)" >&2; exit 2 ;;
  esac
done

# The executable the menu entry runs, as an absolute path (not needed to uninstall).
python="python3"
if [ "$uninstall" = 0 ]; then
  if [ -z "$exec_path" ]; then
    if [ -x "$here/qtanimator" ]; then
      exec_path="$here/qtanimator"
    elif found="$(command -v qtanimator)"; then
      exec_path="$found"
    else
      echo "install-desktop-integration.sh: qtanimator is not on PATH; name it with --exec, e.g." \
        "--exec ~/venvs/qtanimator/bin/qtanimator" >&2
      exit 1
    fi
  fi
  case "$exec_path" in
    /*) ;;
    */*) exec_path="$(cd "$(dirname "$exec_path")" && pwd)/$(basename "$exec_path")" ;;
    *) exec_path="$(command -v "$exec_path" || true)" ;;
  esac
  if [ ! -x "$exec_path" ]; then
    echo "install-desktop-integration.sh: $exec_path is not an executable" >&2
    exit 1
  fi
  # The Python of that installation (a pip script's shebang) finds its desktop files.
  first_line="$(head -n1 "$exec_path" 2>/dev/null | tr -d '\0' || true)"
  case "$first_line" in "#!"*python*) python="${first_line#\#!}" ;; esac
fi

# Where the files are: the bundle, a checkout, or an installed package.
src=""
for candidate in "$here/_internal/qtanimator/resources/desktop" "$here/../resources/desktop"; do
  if [ -f "$candidate/$app_id.desktop" ]; then src="$(cd "$candidate" && pwd)"; break; fi
done
if [ -z "$src" ]; then
  src="$($python -c 'from qtanimator.paths import desktop_dir; print(desktop_dir())' 2>/dev/null || true)"
fi
if [ -z "$src" ] || [ ! -f "$src/$app_id.desktop" ]; then
  echo "install-desktop-integration.sh: cannot find the desktop files ($app_id.desktop)" >&2
  exit 1
fi
apps="$prefix/applications"
icons="$prefix/icons/hicolor/scalable/apps"
mime="$prefix/mime"
metainfo="$prefix/metainfo"

if [ "$uninstall" = 1 ]; then
  rm -f "$apps/$app_id.desktop" "$icons/$app_id.svg" "$mime/packages/$app_id.xml" "$metainfo/$app_id.metainfo.xml"
else
  install -d "$apps" "$icons" "$mime/packages" "$metainfo"
  # The menu entry runs this installation's executable (quoted: the path may hold spaces).
  sed "s|^Exec=qtanimator |Exec=\"${exec_path//|/\\|}\" |" \
    "$src/$app_id.desktop" >"$apps/$app_id.desktop"
  chmod 644 "$apps/$app_id.desktop"
  install -m644 "$src/$app_id.svg" "$icons/$app_id.svg"
  install -m644 "$src/$app_id.mime.xml" "$mime/packages/$app_id.xml"
  install -m644 "$src/$app_id.metainfo.xml" "$metainfo/$app_id.metainfo.xml"
fi
# Refresh the caches where the tools exist (they are optional on a desktop).
if command -v update-mime-database >/dev/null 2>&1; then update-mime-database "$mime" >/dev/null 2>&1 || true; fi
if command -v update-desktop-database >/dev/null 2>&1; then update-desktop-database "$apps" >/dev/null 2>&1 || true; fi
if command -v gtk-update-icon-cache >/dev/null 2>&1; then
  gtk-update-icon-cache -q -t "$prefix/icons/hicolor" >/dev/null 2>&1 || true
fi
if [ "$uninstall" = 1 ]; then
  echo "qtanimator's desktop integration removed from $prefix"
else
  echo "qtanimator's desktop integration installed in $prefix (menu entry runs $exec_path)"
fi
