"""Build hook: puts the fraccloth shared library into the package.

Where the library comes from, in order:
1. FRACCLOTH_LIBRARY: the path of an already built libfraccloth.so;
2. inside the fraccloth repository: `cargo build --release --lib`, then target/release;
3. an installed fraccloth of the same version found by pkg-config (scripts/install.sh).
Otherwise the build stops and says what it needs (an sdist holds the Python package only).

The package itself is pure Python (ctypes): the wheel is tagged py3-none-<platform>, so it
installs on any CPython 3.8+ of the platform the library was built for.
"""

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import setup
from setuptools.command.build_py import build_py

try:  # setuptools >= 70.1 carries bdist_wheel itself
    from setuptools.command.bdist_wheel import bdist_wheel
except ImportError:  # older setuptools: the wheel package's
    from wheel.bdist_wheel import bdist_wheel

HERE = Path(__file__).resolve().parent
REPO = HERE.parent.parent
LIB_NAMES = {"linux": "libfraccloth.so", "darwin": "libfraccloth.dylib", "win32": "fraccloth.dll"}


def library_name():
    for prefix, name in LIB_NAMES.items():
        if sys.platform.startswith(prefix):
            return name
    return "libfraccloth.so"


def package_version():
    text = (HERE / "pyproject.toml").read_text()
    return re.search(r'^version = "([^"]+)"', text, re.M).group(1)


def from_pkg_config():
    version = package_version()
    try:
        libdir = subprocess.run(
            ["pkg-config", "--variable=libdir", f"fraccloth = {version}"],
            check=True, capture_output=True, text=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return None
    candidate = Path(libdir) / f"{library_name()}.{version}"
    return candidate if candidate.exists() else None


def find_or_build_library():
    given = os.environ.get("FRACCLOTH_LIBRARY")
    if given:
        if not Path(given).is_file():
            raise SystemExit(f"fraccloth: FRACCLOTH_LIBRARY={given} is not a file")
        return Path(given)
    if (REPO / "Cargo.toml").exists() and (REPO / "include" / "fraccloth.h").exists():
        subprocess.run(["cargo", "build", "--release", "--lib"], cwd=REPO, check=True)
        built = REPO / "target" / "release" / library_name()
        if built.exists():
            return built
    installed = from_pkg_config()
    if installed:
        return installed
    raise SystemExit(
        "fraccloth: no shared library to package. This source distribution holds the Python "
        "package only, not the Rust library. Either\n"
        "  - set FRACCLOTH_LIBRARY=/path/to/libfraccloth.so (built from the fraccloth repository "
        "with `cargo build --release --lib`), or\n"
        f"  - install fraccloth {package_version()} for C hosts (`bash scripts/install.sh PREFIX` "
        "in the repository) so that pkg-config finds it, or\n"
        "  - run `pip install ./bindings/python` from a clone of the repository (needs cargo)."
    )


class BuildWithLibrary(build_py):
    def run(self):
        super().run()
        dest = Path(self.build_lib) / "fraccloth" / "_lib"
        dest.mkdir(parents=True, exist_ok=True)
        shutil.copy2(find_or_build_library(), dest / library_name())
        # The release build keeps line tables for profiling; the package does not need them
        # (the exported symbols stay): a third of the size.
        strip = shutil.which("strip")
        if strip:
            subprocess.run([strip, "--strip-debug", str(dest / library_name())], check=False)
        # The license texts travel with the wheel.
        for name in ("LICENSE-MIT", "LICENSE-APACHE"):
            if (REPO / name).exists():
                shutil.copy2(REPO / name, dest / name)


class PlatformWheel(bdist_wheel):
    """Pure-Python code beside a native library: py3-none-<platform>."""

    def finalize_options(self):
        super().finalize_options()
        self.root_is_pure = False

    def get_tag(self):
        _, _, platform = super().get_tag()
        return "py3", "none", platform


setup(cmdclass={"build_py": BuildWithLibrary, "bdist_wheel": PlatformWheel})
