"""Build hook: puts the fraccloth shared library and its header into the package.

`pip install ./bindings/python` (from the repository) builds the Rust library with
`cargo build --release --lib` (unless FRACCLOTH_LIBRARY names an already built
libfraccloth.so) and copies it, with include/fraccloth.h, into fraccloth/_lib/.
"""

import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
LIB_NAMES = {"linux": "libfraccloth.so", "darwin": "libfraccloth.dylib", "win32": "fraccloth.dll"}


def library_name():
    for prefix, name in LIB_NAMES.items():
        if sys.platform.startswith(prefix):
            return name
    return "libfraccloth.so"


def find_or_build_library():
    given = os.environ.get("FRACCLOTH_LIBRARY")
    if given:
        return Path(given)
    built = REPO / "target" / "release" / library_name()
    if (REPO / "Cargo.toml").exists():
        subprocess.run(["cargo", "build", "--release", "--lib"], cwd=REPO, check=True)
    if not built.exists():
        raise SystemExit(
            f"fraccloth: no shared library at {built}; build it with `cargo build --release --lib` "
            "or set FRACCLOTH_LIBRARY to its path"
        )
    return built


class BuildWithLibrary(build_py):
    def run(self):
        super().run()
        dest = Path(self.build_lib) / "fraccloth" / "_lib"
        dest.mkdir(parents=True, exist_ok=True)
        shutil.copy2(find_or_build_library(), dest / library_name())
        header = Path(os.environ.get("FRACCLOTH_HEADER", REPO / "include" / "fraccloth.h"))
        shutil.copy2(header, dest / "fraccloth.h")
        # The license texts travel with the wheel.
        for name in ("LICENSE-MIT", "LICENSE-APACHE"):
            if (REPO / name).exists():
                shutil.copy2(REPO / name, dest / name)


class BinaryDistribution(Distribution):
    """The wheel carries a native library: tag it for this platform."""

    def has_ext_modules(self):
        return True


setup(cmdclass={"build_py": BuildWithLibrary}, distclass=BinaryDistribution)
