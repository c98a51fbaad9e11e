"""The native backend's build helpers: a compiler that fails is one named error."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from fsarm_sim.engine.native_abi import NativeBackendError, run_compiler


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
def test_a_failed_compile_is_a_named_error_with_the_compilers_words(tmp_path: Path) -> None:
    bad = tmp_path / "bad.c"
    bad.write_text("int main(void) { return undeclared_name; }\n")
    with pytest.raises(
        NativeBackendError, match=r"(?s)compiling bad\.c failed:\n.*undeclared_name"
    ):
        run_compiler(["cc", str(bad), "-o", str(tmp_path / "bad")], "compiling bad.c")
    good = tmp_path / "good.c"
    good.write_text("int main(void) { return 0; }\n")
    run_compiler(["cc", str(good), "-o", str(tmp_path / "good")], "compiling good.c")
    assert (tmp_path / "good").is_file()
