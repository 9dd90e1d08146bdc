"""The entry points' malloc setting (meshcore._heap): taken on glibc, never set by the library."""

import platform
import subprocess
import sys

import pytest

GLIBC = sys.platform.startswith("linux") and platform.libc_ver()[0] == "glibc"


@pytest.mark.skipif(not GLIBC, reason="mallopt is glibc's")
def test_settings_are_accepted():
    code = "from meshcore._heap import keep_freed_memory; print(keep_freed_memory())"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "True"


def test_cli_sets_it_and_the_library_does_not(monkeypatch):
    import meshcore  # noqa: F401  (importing the library must not touch malloc)
    from meshcore import _heap, cli

    calls = []
    monkeypatch.setattr(_heap, "keep_freed_memory", lambda: calls.append(1) or True)
    assert calls == []
    assert cli.main(["--version"]) == 0
    assert calls == [1]
