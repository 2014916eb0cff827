"""Packaging: licence and metadata, dependency ranges and the constraints files, the wheel and
sdist carry the resources, scenes, docs and desktop files, the desktop integration files are
valid, and the PyInstaller spec names what the frozen app needs."""

from __future__ import annotations

import ast
import configparser
import email
import importlib.util
import re
import shutil
import subprocess
import sys
import tarfile
import tomllib
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import pytest

import qtanimator
from qtanimator import paths

REPO = Path(__file__).resolve().parents[1]
PACKAGING = REPO / "packaging"
APP_ID = paths.APP_ID
DESKTOP_DIR = REPO / "resources" / "desktop"
DESKTOP = DESKTOP_DIR / f"{APP_ID}.desktop"
METAINFO = DESKTOP_DIR / f"{APP_ID}.metainfo.xml"
MIME = DESKTOP_DIR / f"{APP_ID}.mime.xml"
ICON = DESKTOP_DIR / f"{APP_ID}.svg"
SPEC = PACKAGING / "qtanimator.spec"
DESKTOP_FILES = (DESKTOP, METAINFO, MIME, ICON)
#: The user documentation shipped in the package (the Help menu shows the first two).
USER_DOCS = ("user-guide.md", "keyboard.md", "formats.md")


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
    assert mapping == {"qtanimator.resources": "resources", "qtanimator.scenes": "scenes", "qtanimator.docs": "docs"}
    for folder in mapping.values():
        assert (REPO / folder).is_dir()
    assert {"qtanimator.resources", "qtanimator.scenes", "qtanimator.docs"} <= listed


def test_checkout_finds_its_resources_and_scenes() -> None:
    # In a checkout (and the editable install) the folders at the repository root are used.
    if Path(qtanimator.__file__).resolve().parent != REPO / "qtanimator":
        # CI's newest and oldest sets run the suite against the installed wheel, whose own
        # folders test_wheel_contains_package_resources_and_scenes and .ci/wheel_check.sh check.
        pytest.skip("qtanimator is the installed wheel here, not the checkout")
    assert paths.shader_path("mesh.vert").is_file()
    assert (paths.scenes_dir() / "flappy.svg").is_file()
    assert paths.demo_project().is_file()
    assert paths.app_icon_path().is_file() and paths.desktop_dir() == DESKTOP_DIR
    for name in USER_DOCS:
        assert (paths.docs_dir() / name).is_file()


# ------------------------------------------------------------------ licence and metadata
def test_licence_and_project_metadata() -> None:
    project = _pyproject()["project"]
    assert project["license"] == "MIT" and project["license-files"] == ["LICENSE"]
    licence = (REPO / "LICENSE").read_text(encoding="utf-8")
    assert licence.startswith("MIT License") and "qtanimator contributors" in licence
    assert project["authors"] == [{"name": "qtanimator contributors"}]
    assert len(project["keywords"]) >= 5 and len(project["classifiers"]) >= 5
    # PEP 639: a licence expression replaces the licence classifiers (setuptools refuses both).
    assert not [c for c in project["classifiers"] if c.startswith("License ::")]
    requires = _pyproject()["build-system"]["requires"]
    assert any(re.fullmatch(r"setuptools>=(7[7-9]|[89]\d)(\.\d+)*", r) for r in requires), requires
    for label, url in project["urls"].items():
        # No public host yet: the links name documents of the repository (and the sdist).
        assert (REPO / url).is_file(), (label, url)
    assert "readme" in project["dynamic"]


def test_the_long_description_has_no_relative_image_links() -> None:
    """On PyPI a relative image link is a broken picture: setup.py drops the screenshots."""
    spec = importlib.util.spec_from_file_location("qtanimator_setup", REPO / "setup.py")
    assert spec is not None and spec.loader is not None
    source = (REPO / "setup.py").read_text(encoding="utf-8").replace("\nsetup(", "\n_unused = dict(")
    namespace: dict[str, object] = {"__file__": str(REPO / "setup.py"), "__name__": "qtanimator_setup"}
    exec(compile(source, str(REPO / "setup.py"), "exec"), namespace)
    readme = (REPO / "README.md").read_text(encoding="utf-8")
    assert "![" in readme  # the repository's README keeps its screenshots
    text = namespace["long_description"](readme)  # type: ignore[operator]
    assert "![" not in text and "docs/images" not in text and "| |" not in text
    assert not re.search(r"\]\((?!https?://|#)", text), "a relative link is left"
    assert "## Quick start" in text and "./dev.sh run" in text and "`docs/user-guide.md`" in text


# ------------------------------------------------------------------ dependencies
#: Releases known to crash the program, each with the Pythons it crashes on (issue 30): PySide6
#: 6.12.0's shiboken drops a reference to None on every method that returns nothing, which
#: aborts Python < 3.12 ("none_dealloc"; None is immortal from 3.12).
KNOWN_CRASHES = {"pyside6-essentials": [("6.12.0", ("3.11",))], "shiboken6": [("6.12.0", ("3.11",))]}


def _requirements(items: list[str], python: str = "3.11") -> dict[str, str]:
    """name -> specifier of the requirements that apply on ``python`` (markers evaluated)."""
    from packaging.requirements import Requirement

    out = {}
    for item in items:
        req = Requirement(item)
        if req.marker is None or req.marker.evaluate({"python_version": python, "python_full_version": python + ".0",
                                                      "extra": ""}):
            name = _norm(req.name)
            assert name not in out, f"two requirements of {name} apply on Python {python}"
            out[name] = str(req.specifier)
    return out


def _norm(name: str) -> str:
    return re.sub(r"[-_.]+", "-", name).lower()


def _pins(path: Path) -> dict[str, str]:
    pins = {}
    for line in path.read_text(encoding="utf-8").splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            name, _, version = line.partition("==")
            assert version, f"{path.name}: {line!r} is not an exact pin"
            pins[_norm(name)] = version
    return pins


def test_install_metadata_has_ranges_and_the_constraints_pin_exactly() -> None:
    from packaging.specifiers import SpecifierSet

    project = _pyproject()["project"]
    deps = _requirements(project["dependencies"])
    extras = project["optional-dependencies"]
    # numba is a dependency (issue 30: the compiled cloth is what a plain install must get).
    assert deps.get("numba") == ">=0.60" and "fast" not in extras
    for name, spec in deps.items():
        assert "==" not in spec and ">=" in spec, f"{name}{spec}: a range with a lower bound, never a pin"
    pins = _pins(REPO / "constraints.txt")
    lower = _pins(REPO / "constraints-min.txt")
    for name, spec in {**deps, **_requirements(extras["test"])}.items():
        assert name in pins, f"constraints.txt pins no version of {name}"
        assert pins[name] in SpecifierSet(spec), f"constraints.txt: {name}=={pins[name]} is outside {spec}"
    for name, spec in deps.items():
        bound = re.search(r">=([0-9.]+)", spec)
        assert bound and name in lower, f"constraints-min.txt has no {name}"
        assert lower[name] == bound.group(1) or lower[name].startswith(bound.group(1) + "."), (
            f"the tested lower bound of {name} is {lower[name]}, but pyproject.toml says {spec}")
        assert lower[name] in SpecifierSet(spec), f"constraints-min.txt: {name}=={lower[name]} is outside {spec}"
    # ./dev.sh and CI install with the constraints.
    assert '-c constraints.txt' in (REPO / "dev.sh").read_text(encoding="utf-8")


@pytest.mark.parametrize("python", ["3.11", "3.12", "3.13"])
def test_install_metadata_excludes_the_releases_known_to_crash(python: str) -> None:
    """pip must never pick a release that aborts the interpreter (issue 30: PySide6 6.12.0 on
    Python 3.11 was what every `pip install qtanimator` got)."""
    from packaging.specifiers import SpecifierSet

    deps = _requirements(_pyproject()["project"]["dependencies"], python)
    assert "pyside6-essentials" in deps
    for name, crashes in KNOWN_CRASHES.items():
        for version, pythons in crashes:
            if python in pythons:
                # shiboken6 comes in through PySide6-Essentials, which pins its own release exactly.
                spec = deps.get(name, deps["pyside6-essentials"])
                assert version not in SpecifierSet(spec), f"{name} {version} crashes on Python {python}: {spec}"
    # Where it does not crash the release stays allowed (the exclusion is as narrow as the cause).
    if python != "3.11":
        assert "6.12.0" in SpecifierSet(deps["pyside6-essentials"])


def _copy_sources(dest: Path) -> Path:
    """A copy of what the build reads (so nothing is written into the checkout)."""
    src = dest / "src"
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc", "*.nbi", "*.nbc", "*.egg-info")
    for name in ("qtanimator", "resources", "scenes", "docs"):
        shutil.copytree(REPO / name, src / name, ignore=ignore)
    for name in ("pyproject.toml", "setup.py", "README.md", "LICENSE"):
        shutil.copy2(REPO / name, src / name)
    return src


def _build_wheel(dest: Path, src: Path | None = None) -> Path:
    if importlib.util.find_spec("wheel") is None or importlib.util.find_spec("setuptools") is None:
        pytest.skip("setuptools and wheel are needed to build without isolation (pip install setuptools wheel)")
    src = src or _copy_sources(dest)
    out = dest / "wheel"
    proc = subprocess.run([sys.executable, "-m", "pip", "wheel", str(src), "--no-deps", "--no-build-isolation",
                           "--no-index", "-q", "-w", str(out)], capture_output=True, text=True, timeout=240)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "Package would be ignored" not in proc.stderr
    assert "SetuptoolsDeprecationWarning" not in proc.stderr, proc.stderr
    (wheel,) = out.glob("qtanimator-*.whl")
    return wheel


@pytest.mark.slow
def test_sdist_then_wheel_carry_licence_docs_and_desktop_files(tmp_path: Path) -> None:
    """pip builds the wheel from the sdist: the sdist must hold everything the wheel needs."""
    if importlib.util.find_spec("setuptools") is None:
        pytest.skip("setuptools is needed to build the sdist")
    src = _copy_sources(tmp_path)
    code = ("import sys; from setuptools import build_meta as b; "
            "print(b.build_sdist(sys.argv[1]))")
    proc = subprocess.run([sys.executable, "-c", code, str(tmp_path / "sdist")], cwd=src, capture_output=True,
                          text=True, timeout=240)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    sdist = tmp_path / "sdist" / proc.stdout.strip().splitlines()[-1]
    with tarfile.open(sdist) as tar:
        names = {n.split("/", 1)[1] for n in tar.getnames() if "/" in n}
        tar.extractall(tmp_path / "unpacked", filter="data")
    for must in ("LICENSE", "README.md", "setup.py", "pyproject.toml", "resources/desktop/" + DESKTOP.name,
                 "docs/user-guide.md", "docs/images/main_window.png", "scenes/demo/demo.qtanim"):
        assert must in names, must
    (root,) = (tmp_path / "unpacked").iterdir()
    wheel = _build_wheel(tmp_path, root)
    assert "qtanimator/resources/desktop/" + DESKTOP.name in zipfile.ZipFile(wheel).namelist()


@pytest.mark.slow
def test_wheel_contains_package_resources_and_scenes(tmp_path: Path) -> None:
    wheel = _build_wheel(tmp_path)
    assert wheel.name == f"qtanimator-{qtanimator.__version__}-py3-none-any.whl"
    archive = zipfile.ZipFile(wheel)
    names = set(archive.namelist())
    for shader in (REPO / "resources" / "shaders").iterdir():
        assert f"qtanimator/resources/shaders/{shader.name}" in names
    for desktop_file in DESKTOP_FILES:
        assert f"qtanimator/resources/desktop/{desktop_file.name}" in names
    for doc in USER_DOCS:
        assert f"qtanimator/docs/{doc}" in names
    for image in (REPO / "docs" / "images").glob("*.png"):
        assert f"qtanimator/docs/images/{image.name}" in names
    assert "qtanimator/docs/decisions.md" not in names and "qtanimator/docs/contributing.md" not in names
    scene_files = [p for p in (REPO / "scenes").rglob("*") if p.is_file() and "__pycache__" not in p.parts]
    assert len(scene_files) > 10
    for p in scene_files:
        assert f"qtanimator/scenes/{p.relative_to(REPO / 'scenes').as_posix()}" in names, p
    for must in ("qtanimator/cli.py", "qtanimator/paths.py", "qtanimator/core/channel.py",
                 "qtanimator/ui/main_window.py", "qtanimator/ui/errors.py", "qtanimator/render/gl/__init__.py"):
        assert must in names
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]
    dist_info = f"qtanimator-{qtanimator.__version__}.dist-info"
    assert f"{dist_info}/licenses/LICENSE" in names
    text = archive.read(f"{dist_info}/entry_points.txt").decode()
    assert "qtanimator = qtanimator.cli:main" in text
    meta = email.message_from_bytes(archive.read(f"{dist_info}/METADATA"))
    assert meta["License-Expression"] == "MIT" and meta["License-File"] == "LICENSE"
    assert meta["Author"] == "qtanimator contributors" or "qtanimator contributors" in (meta["Author-email"] or "")
    assert meta["Keywords"] and meta.get_all("Classifier")
    requires = meta.get_all("Requires-Dist") or []
    assert not [r for r in requires if "==" in r.split(";")[0]], requires
    assert "numba>=0.60" in requires
    assert 'PySide6-Essentials!=6.12.0,<7,>=6.8.1; python_version < "3.12"' in requires, requires
    body = meta.get_payload()
    assert meta["Description-Content-Type"] == "text/markdown"
    assert "## Quick start" in body and "![" not in body


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
    # Only the project type: claiming image/svg+xml offered qtanimator for every SVG on the system.
    assert e["MimeType"] == "application/x-qtanimator-project;"
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
    assert root.findtext("project_license") == project["license"]
    assert root.findtext("developer_name") == "qtanimator contributors"
    release = next(root.iter("release"))
    assert release.find("description/p") is not None
    # No <url> or <screenshots> until qtanimator has a public address: AppStream accepts only
    # absolute http(s) URLs there (a repository-relative docs/images/*.png is refused).
    for url in root.iter("url"):
        assert (url.text or "").startswith("https://"), url.text
    for image in root.iter("image"):
        assert (image.text or "").startswith("https://"), image.text
    exe = shutil.which("appstreamcli")
    if exe:
        proc = subprocess.run([exe, "validate", "--strict", "--no-net", str(METAINFO)], capture_output=True,
                              text=True, timeout=60)
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
                 "imageio_ffmpeg", "qtanimator/resources", "qtanimator/scenes", "qtanimator/docs", "resources",
                 "scenes", "user-guide.md", "keyboard.md"):
        assert name in strings, name
    calls = {n.func.id for n in ast.walk(tree) if isinstance(n, ast.Call) and isinstance(n.func, ast.Name)}
    assert {"Analysis", "PYZ", "EXE", "COLLECT"} <= calls  # a one-folder app
    entry = PACKAGING / "qtanimator_main.py"
    assert entry.is_file() and "qtanimator.cli import main" in entry.read_text(encoding="utf-8")
    # Every module the main window imports by name is a real module that collect_submodules finds.
    from qtanimator.ui.main_window import EDITOR_MODULES

    for mod in EDITOR_MODULES:
        assert importlib.util.find_spec(mod) is not None, mod
    # The bundle's desktop integration installer ships beside the executable.
    installer = PACKAGING / "install-desktop-integration.sh"
    assert installer.is_file() and installer.stat().st_mode & 0o111
    assert "install-desktop-integration.sh" in (PACKAGING / "build_app.sh").read_text(encoding="utf-8")


def test_desktop_integration_installer_puts_the_files_in_place(tmp_path: Path) -> None:
    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash is not installed")
    exe = tmp_path / "qt animator" / "qtanimator"
    exe.parent.mkdir()
    exe.write_text("#!/bin/sh\n", encoding="utf-8")
    exe.chmod(0o755)
    proc = subprocess.run([bash, str(PACKAGING / "install-desktop-integration.sh"), "--prefix", str(tmp_path),
                           "--exec", str(exe)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    entry = tmp_path / "applications" / DESKTOP.name
    assert f'Exec="{exe}" %f' in entry.read_text(encoding="utf-8")
    assert (tmp_path / "icons/hicolor/scalable/apps" / ICON.name).read_bytes() == ICON.read_bytes()
    assert (tmp_path / "metainfo" / METAINFO.name).read_bytes() == METAINFO.read_bytes()
    assert (tmp_path / "mime/packages" / f"{APP_ID}.xml").read_bytes() == MIME.read_bytes()
    validate = shutil.which("desktop-file-validate")
    if validate:
        check = subprocess.run([validate, str(entry)], capture_output=True, text=True, timeout=30)
        assert check.returncode == 0, check.stdout + check.stderr


def _fake_install(root: Path) -> Path:
    """A venv-like bin folder: a `qtanimator` script whose shebang is this test's Python."""
    bin_dir = root / "venv" / "bin"
    bin_dir.mkdir(parents=True)
    exe = bin_dir / "qtanimator"
    exe.write_text(f"#!{sys.executable}\nimport sys\nfrom qtanimator.cli import main\nsys.exit(main())\n",
                   encoding="utf-8")
    exe.chmod(0o755)
    return exe


def test_desktop_integration_runs_the_absolute_path_of_the_qtanimator_on_path(tmp_path: Path) -> None:
    """A venv or pipx install: the desktop session's PATH lacks its bin folder, so a bare
    `Exec=qtanimator` would be hidden; the entry names the executable found now (issue 30)."""
    import os

    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash is not installed")
    exe = _fake_install(tmp_path)
    prefix = tmp_path / "share"
    env = {**os.environ, "PATH": f"{exe.parent}:/usr/bin:/bin"}
    # Run from another folder, as a user would after `cd ~`.
    proc = subprocess.run([bash, str(PACKAGING / "install-desktop-integration.sh"), "--prefix", str(prefix)],
                          capture_output=True, text=True, timeout=60, env=env, cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    entry = (prefix / "applications" / DESKTOP.name).read_text(encoding="utf-8")
    assert f'Exec="{exe}" %f' in entry, entry
    # A relative --exec is made absolute too.
    proc = subprocess.run([bash, str(PACKAGING / "install-desktop-integration.sh"), "--prefix", str(prefix),
                           "--exec", "venv/bin/qtanimator"], capture_output=True, text=True, timeout=60, env=env,
                          cwd=tmp_path)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert f'Exec="{exe}" %f' in (prefix / "applications" / DESKTOP.name).read_text(encoding="utf-8")


def test_desktop_integration_without_qtanimator_on_path_says_how_to_name_it(tmp_path: Path) -> None:
    import os

    bash = shutil.which("bash")
    if bash is None:
        pytest.skip("bash is not installed")
    proc = subprocess.run([bash, str(PACKAGING / "install-desktop-integration.sh"), "--prefix", str(tmp_path)],
                          capture_output=True, text=True, timeout=60, env={**os.environ, "PATH": "/usr/bin:/bin"})
    assert proc.returncode == 1 and "--exec" in proc.stderr, proc.stderr
    assert not (tmp_path / "applications").exists()


# ------------------------------------------------------------------ numba
def test_qtanimator_no_numba_forces_the_numpy_kernels() -> None:
    """CI runs the cloth tests a second time with QTANIMATOR_NO_NUMBA=1: the numpy kernels, the
    path of a platform without numba and of the frozen app."""
    import os

    code = ("import sys; from qtanimator.core import cloth_kernels; from qtanimator.core.cloth import Cloth; "
            "print(cloth_kernels.HAVE_NUMBA, Cloth().accelerated, 'numba' in sys.modules)")
    for value, expect in (("1", "False False False"), ("0", None)):
        env = {**os.environ, "QTANIMATOR_NO_NUMBA": value}
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, timeout=120,
                             check=True).stdout.split()
        if expect is not None:
            assert out == expect.split()
        else:  # "0" does not switch it off
            assert out[0] == str(importlib.util.find_spec("numba") is not None)
    if os.environ.get("QTANIMATOR_NO_NUMBA", "") not in ("", "0"):
        from qtanimator.core import cloth_kernels

        assert not cloth_kernels.HAVE_NUMBA
