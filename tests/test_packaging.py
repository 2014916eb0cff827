"""Packaging: the wheel carries resources and scenes, the desktop integration files are valid,
and the PyInstaller spec names what the frozen app needs."""

from __future__ import annotations

import ast
import configparser
import importlib.util
import shutil
import subprocess
import sys
import tomllib
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

import qtanimator
from qtanimator import paths

REPO = Path(__file__).resolve().parents[1]
PACKAGING = REPO / "packaging"
APP_ID = "io.github.qtanimator.qtanimator"
DESKTOP = PACKAGING / f"{APP_ID}.desktop"
METAINFO = PACKAGING / f"{APP_ID}.metainfo.xml"
MIME = PACKAGING / f"{APP_ID}.mime.xml"
ICON = PACKAGING / "qtanimator.svg"
SPEC = PACKAGING / "qtanimator.spec"


def _pyproject() -> dict:
    return tomllib.loads((REPO / "pyproject.toml").read_text(encoding="utf-8"))


# ------------------------------------------------------------------ wheel configuration
def test_every_subpackage_is_listed_for_the_wheel() -> None:
    """Sub-packages are listed by hand in pyproject (mapped folders rule out packages.find)."""
    st = _pyproject()["tool"]["setuptools"]
    listed = set(st["packages"])
    on_disk = {".".join(p.parent.relative_to(REPO).parts) for p in (REPO / "qtanimator").rglob("__init__.py")}
    assert on_disk, "no packages found"
    missing = on_disk - listed
    assert not missing, f"add {sorted(missing)} to [tool.setuptools] packages in pyproject.toml"
    mapping = st["package-dir"]
    assert mapping == {"qtanimator.resources": "resources", "qtanimator.scenes": "scenes"}
    for folder in mapping.values():
        assert (REPO / folder).is_dir()
    assert {"qtanimator.resources", "qtanimator.scenes"} <= listed


def test_checkout_finds_its_resources_and_scenes() -> None:
    # In a checkout (and the editable install) the folders at the repository root are used.
    assert paths.shader_path("mesh.vert").is_file()
    assert (paths.scenes_dir() / "flappy.svg").is_file()
    assert paths.demo_project().is_file()


def _build_wheel(dest: Path) -> Path:
    """Build a wheel from a copy of the sources (so nothing is written into the checkout)."""
    if importlib.util.find_spec("wheel") is None or importlib.util.find_spec("setuptools") is None:
        pytest.skip("setuptools and wheel are needed to build without isolation (pip install setuptools wheel)")
    src = dest / "src"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc", "*.egg-info")
    for name in ("qtanimator", "resources", "scenes"):
        shutil.copytree(REPO / name, src / name, ignore=ignore)
    for name in ("pyproject.toml", "README.md", "LICENSE"):
        if (REPO / name).exists():
            shutil.copy2(REPO / name, src / name)
    out = dest / "wheel"
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "--no-build-isolation",
                           "--no-index", "-q", "-w", str(out)], capture_output=True, text=True, timeout=240)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Package would be ignored" not in proc.stderr
    (wheel,) = out.glob("qtanimator-*.whl")
    return wheel


@pytest.mark.slow
def test_wheel_contains_package_resources_and_scenes(tmp_path: Path) -> None:
    wheel = _build_wheel(tmp_path)
    assert wheel.name == f"qtanimator-{qtanimator.__version__}-py3-none-any.whl"
    names = set(zipfile.ZipFile(wheel).namelist())
    for shader in (REPO / "resources" / "shaders").iterdir():
        assert f"qtanimator/resources/shaders/{shader.name}" in names
    scene_files = [p for p in (REPO / "scenes").rglob("*") if p.is_file() and "__pycache__" not in p.parts]
    assert len(scene_files) > 10
    for p in scene_files:
        assert f"qtanimator/scenes/{p.relative_to(REPO / 'scenes').as_posix()}" in names, p
    for must in ("qtanimator/cli.py", "qtanimator/paths.py", "qtanimator/core/channel.py",
                 "qtanimator/ui/main_window.py", "qtanimator/render/gl/__init__.py"):
        assert must in names
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]
    entry = next(n for n in names if n.endswith(".dist-info/entry_points.txt"))
    text = zipfile.ZipFile(wheel).read(entry).decode()
    assert "qtanimator = qtanimator.cli:main" in text


# ------------------------------------------------------------------ desktop integration
def test_desktop_entry_is_valid() -> None:
    cp = configparser.ConfigParser(interpolation=None, strict=True)
    cp.optionxform = str  # type: ignore[assignment,method-assign]  # keys are case-sensitive
    cp.read(DESKTOP, encoding="utf-8")
    e = cp["Desktop Entry"]
    assert e["Type"] == "Application"
    for key in ("Name", "Exec", "Icon", "Categories", "Comment"):
        assert e.get(key), key
    assert e["Exec"].split()[0] == "qtanimator"
    assert e["Icon"] == APP_ID and ICON.is_file()
    assert e["Categories"].endswith(";") and "Graphics" in e["Categories"].split(";")
    assert e["Terminal"] == "false"
    assert "application/x-qtanimator-project" in e["MimeType"].split(";")
    exe = shutil.which("desktop-file-validate")
    if exe:
        proc = subprocess.run([exe, str(DESKTOP)], capture_output=True, text=True, timeout=30)
        assert proc.returncode == 0 and "error" not in proc.stdout.lower(), proc.stdout + proc.stderr


def test_appstream_metainfo_is_valid() -> None:
    root = ET.parse(METAINFO).getroot()
    assert root.tag == "component" and root.get("type") == "desktop-application"
    assert root.findtext("id") == APP_ID
    for tag in ("name", "summary", "metadata_license", "project_license"):
        assert (root.findtext(tag) or "").strip(), tag
    assert root.find("description/p") is not None
    launch = root.find("launchable")
    assert launch is not None and launch.get("type") == "desktop-id" and launch.text == DESKTOP.name
    assert root.findtext("provides/binary") == "qtanimator"
    versions = [r.get("version") for r in root.iter("release")]
    assert qtanimator.__version__ in versions
    project = _pyproject()["project"]
    assert root.findtext("project_license") == project["license"]["text"]
    exe = shutil.which("appstreamcli")
    if exe:
        proc = subprocess.run([exe, "validate", "--no-net", str(METAINFO)], capture_output=True, text=True,
                              timeout=60)
        assert proc.returncode == 0, proc.stdout + proc.stderr


def test_mime_type_and_icon() -> None:
    ns = {"m": "http://www.freedesktop.org/standards/shared-mime-info"}
    root = ET.parse(MIME).getroot()
    mt = root.find("m:mime-type", ns)
    assert mt is not None and mt.get("type") == "application/x-qtanimator-project"
    glob = mt.find("m:glob", ns)
    assert glob is not None and glob.get("pattern") == "*.qtanim"
    svg = ET.parse(ICON).getroot()
    assert svg.tag.endswith("svg")
    x, y, w, h = (float(v) for v in svg.get("viewBox", "").split())
    assert w == h > 0  # desktop icons are square


# ------------------------------------------------------------------ PyInstaller
def test_pyinstaller_spec_bundles_what_the_app_loads_at_run_time() -> None:
    source = SPEC.read_text(encoding="utf-8")
    tree = ast.parse(source)  # valid Python
    strings = {n.value for n in ast.walk(tree) if isinstance(n, ast.Constant) and isinstance(n.value, str)}
    for name in ("PySide6.QtOpenGL", "PySide6.QtOpenGLWidgets", "OpenGL.platform.egl", "qtanimator", "pyqtgraph",
                 "imageio_ffmpeg", "qtanimator/resources", "qtanimator/scenes", "resources", "scenes"):
        assert name in strings, name
    calls = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
    assert {"Analysis", "PYZ", "EXE", "COLLECT"} <= calls  # a one-folder app
    entry = PACKAGING / "qtanimator_main.py"
    assert entry.is_file() and "qtanimator.cli import main" in entry.read_text(encoding="utf-8")
    # Every module the main window imports by name is a real module that collect_submodules finds.
    from qtanimator.ui.main_window import EDITOR_MODULES

    for mod in EDITOR_MODULES:
        assert importlib.util.find_spec(mod) is not None, mod
