"""A pytest plugin for tools/mutation.py: which tests run which lines of one module.

Loaded with ``-p mutation_trace`` (tools/ on PYTHONPATH). ``MUTATION_TRACE_FILE`` names the
module's source file; at the end of the session ``MUTATION_TRACE_OUT`` gets JSON
``{"order": [nodeid, ...], "lines": {nodeid: [line, ...]}}``, where the node id ``""`` holds
the lines run outside any test (while importing and collecting: module constants, defaults).
Tracing (``sys.settrace``) only follows frames of that one file, so the other code runs with
the cost of one call per Python function call.
"""

from __future__ import annotations

import json
import os
import sys
import threading
from collections.abc import Generator
from types import FrameType
from typing import Any

import pytest

_TARGET = os.path.realpath(os.environ.get("MUTATION_TRACE_FILE", ""))
_lines: dict[str, set[int]] = {"": set()}
_order: list[str] = []
_current = [""]
_is_target: dict[str, bool] = {}


def _local(frame: FrameType, event: str, _arg: Any) -> Any:
    if event == "line":
        _lines[_current[0]].add(frame.f_lineno)
    return _local


def _global(frame: FrameType, event: str, _arg: Any) -> Any:
    if event != "call":
        return None
    name = frame.f_code.co_filename
    hit = _is_target.get(name)
    if hit is None:
        hit = _is_target[name] = os.path.realpath(name) == _TARGET
    if not hit:
        return None
    _lines[_current[0]].add(frame.f_lineno)
    return _local


def pytest_configure(config: pytest.Config) -> None:
    if _TARGET:
        sys.settrace(_global)
        threading.settrace(_global)


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Generator[None, None, None]:
    _current[0] = item.nodeid
    _lines.setdefault(item.nodeid, set())
    _order.append(item.nodeid)
    sys.settrace(_global)  # again: a test may have replaced it (a debugger, hypothesis' explain phase)
    yield
    _current[0] = ""


def pytest_sessionfinish(session: pytest.Session, exitstatus: int) -> None:
    sys.settrace(None)
    threading.settrace(None)  # type: ignore[arg-type]
    out = os.environ.get("MUTATION_TRACE_OUT")
    if out:
        with open(out, "w", encoding="utf-8") as f:
            json.dump({"order": _order, "lines": {k: sorted(v) for k, v in _lines.items()}}, f)
