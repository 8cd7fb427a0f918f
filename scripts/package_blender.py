#!/usr/bin/env python3
"""Packages the Blender add-on as a Blender 4.2+ extension: a zip with the add-on, its
`blender_manifest.toml` and the `fraccloth` wheel it imports (Blender installs the wheel).

Usage: python3 scripts/package_blender.py WHEEL [OUT_DIR]   (default OUT_DIR target/blender)
Install: Blender > Edit > Preferences > Get Extensions > Install from Disk, choose the zip.
Prints the zip's path.
"""

import re
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
ADDON = ROOT / "bindings" / "blender" / "fraccloth_blender"

# Blender's platform names for the wheel's platform tags.
PLATFORMS = {"linux_x86_64": "linux-x64", "linux_aarch64": "linux-arm64", "macosx": "macos", "win_amd64": "windows-x64"}


def version():
    text = (ROOT / "Cargo.toml").read_text()
    return re.search(r'^version = "([^"]+)"', text, re.M).group(1)


def platform_of(wheel: Path):
    tag = wheel.stem.split("-")[-1]
    for key, name in PLATFORMS.items():
        if key in tag:
            return name
    raise SystemExit(f"{wheel.name}: no Blender platform for the wheel tag {tag}")


def manifest(v, wheel: Path):
    return f'''schema_version = "1.0.0"
id = "fraccloth"
version = "{v}"
name = "fraccloth underwater cloth"
tagline = "Bake cloth that moves as if underwater, to a point cache"
maintainer = "fraccloth developers"
type = "add-on"
blender_version_min = "4.2.0"
license = ["SPDX:MIT", "SPDX:Apache-2.0"]
platforms = ["{platform_of(wheel)}"]
wheels = ["./wheels/{wheel.name}"]

[permissions]
files = "Writes the baked point cache (PC2 or MDD) next to the .blend or where you choose"
'''


def main():
    if len(sys.argv) < 2:
        raise SystemExit(__doc__)
    wheel = Path(sys.argv[1]).resolve()
    if not wheel.is_file() or wheel.suffix != ".whl":
        raise SystemExit(f"{wheel}: not a wheel (build one: pip wheel --no-deps -w target/wheels ./bindings/python)")
    v = version()
    if f"-{v}-" not in wheel.name:
        raise SystemExit(f"{wheel.name} is not fraccloth {v}")
    out = Path(sys.argv[2]) if len(sys.argv) > 2 else ROOT / "target" / "blender"
    out.mkdir(parents=True, exist_ok=True)
    path = out / f"fraccloth_blender-{v}.zip"
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        for f in sorted(ADDON.rglob("*.py")):
            z.write(f, f.relative_to(ADDON).as_posix())
        z.writestr("blender_manifest.toml", manifest(v, wheel))
        z.write(wheel, f"wheels/{wheel.name}")
    print(path)


if __name__ == "__main__":
    main()
