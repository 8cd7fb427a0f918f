"""Installs the packaged extension (scripts/package_blender.py) into a fresh Blender user folder
with real `bpy`, enables it, and checks that the add-on registered and that Blender unpacked the
fraccloth wheel it carries. Exits non-zero on any failure.

Usage (with a HOME of its own): python check_extension.py fraccloth_blender-VERSION.zip
"""

import os
import sys
from pathlib import Path

import bpy

zip_path = sys.argv[1]
result = bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
assert result == {"FINISHED"}, result
assert "bl_ext.user_default.fraccloth" in sys.modules, "the extension did not enable"
assert hasattr(bpy.types.Object, "fraccloth"), "the add-on's settings are not registered"
assert hasattr(bpy.ops.fraccloth, "bake") and hasattr(bpy.ops.fraccloth, "free_bake")
base = Path(bpy.utils.user_resource("EXTENSIONS"))
libs = list(base.rglob("fraccloth/_lib/libfraccloth.*"))
assert libs, f"no unpacked fraccloth library under {base}"
print(f"extension installed and enabled; its wheel unpacked to {libs[0].parent.parent} ({os.path.getsize(libs[0])} bytes)")
