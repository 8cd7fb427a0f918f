"""The add-on in real Blender (the `bpy` module): enable it headless, bake a small scene, read
the evaluated mesh back at several frames and compare it with the library's own positions.

Run with a Python that has `bpy` and the `fraccloth` package installed (see .ci/blender).
"""

import sys
from pathlib import Path

import numpy as np
import pytest

bpy = pytest.importorskip("bpy")
import addon_utils  # noqa: E402  (part of bpy)

ADDON_DIR = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def addon():
    if str(ADDON_DIR) not in sys.path:
        sys.path.insert(0, str(ADDON_DIR))
    bpy.ops.wm.read_factory_settings(use_empty=True)
    mod = addon_utils.enable("fraccloth_blender", default_set=True, handle_error=None)
    assert mod is not None, "the add-on did not enable"
    assert hasattr(bpy.types.Scene, "fraccloth")
    yield mod
    addon_utils.disable("fraccloth_blender")


def make_scene(tmp_path, fmt):
    # Start empty (read_factory_settings here would also disable the add-on).
    for o in list(bpy.data.objects):
        bpy.data.objects.remove(o)
    for m in list(bpy.data.meshes):
        bpy.data.meshes.remove(m)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    scene.render.fps = 24
    # A 0.3 m square cloth of 13 x 9 vertices, lying in the x-y plane 20 cm up, moved and
    # turned so the local frame is not the world frame.
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=12, y_subdivisions=8, size=0.3, location=(0.1, -0.2, 0.2),
                                    rotation=(0.0, 0.0, 0.3))
    cloth = bpy.context.active_object
    group = cloth.vertex_groups.new(name="pins")
    ys = [v.co.y for v in cloth.data.vertices]
    edge = [v.index for v in cloth.data.vertices if v.co.y > max(ys) - 1e-6]
    group.add(edge, 1.0, "REPLACE")
    # A ball under the middle of the cloth and a floor.
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.05, location=(0.1, -0.2, 0.1))
    ball = bpy.context.active_object
    bpy.ops.mesh.primitive_plane_add(size=2.0, location=(0.0, 0.0, -0.1))
    floor = bpy.context.active_object
    for o in (ball, floor):
        o.select_set(True)
    cloth.select_set(True)
    bpy.context.view_layer.objects.active = cloth
    s = scene.fraccloth
    s.cache_format = fmt
    s.cache_path = str(tmp_path / "cloth")
    s.integrator = "SYMPLECTIC"
    s.time_step = 1e-3
    s.current = (0.05, 0.0, 0.0)
    s.friction = 0.2
    return cloth, [ball, floor]


def evaluated(obj, frame):
    bpy.context.scene.frame_set(frame)
    deps = bpy.context.evaluated_depsgraph_get()
    me = obj.evaluated_get(deps).to_mesh()
    co = np.empty(3 * len(me.vertices), dtype=np.float32)
    me.vertices.foreach_get("co", co)
    obj.evaluated_get(deps).to_mesh_clear()
    return co.reshape(-1, 3)


@pytest.mark.parametrize("fmt", ["PC2", "MDD"])
def test_bake_reads_back_exactly(addon, tmp_path, fmt):
    cloth, others = make_scene(tmp_path, fmt)
    rest = np.array([v.co[:] for v in cloth.data.vertices], dtype=np.float32)
    result = bpy.ops.fraccloth.bake()
    assert result == {"FINISHED"}
    mod = cloth.modifiers.get("fraccloth")
    assert mod is not None and mod.type == "MESH_CACHE" and mod.cache_format == fmt
    assert Path(mod.filepath).exists()
    # The library's own positions: the add-on's simulation, run again with the same inputs.
    expected = {f: c.positions.copy() for f, c in addon.simulate(bpy.context, cloth, others)}
    for frame in (1, 2, 12, 24):
        got = evaluated(cloth, frame)
        assert got.shape == expected[frame].shape
        assert np.array_equal(got, expected[frame]), f"frame {frame}: max diff {np.abs(got - expected[frame]).max()}"
    # It moved: the free edge sagged, the pinned edge stayed.
    last = expected[24]
    assert np.abs(last - rest).max() > 0.01
    pinned = [v.index for v in cloth.data.vertices if v.groups]
    assert np.array_equal(last[pinned], rest[pinned])


def test_bad_input_is_reported_not_crashed(addon, tmp_path):
    cloth, _ = make_scene(tmp_path, "PC2")
    cloth.scale = (2.0, 1.0, 1.0)
    bpy.context.view_layer.update()
    with pytest.raises(RuntimeError, match="apply its scale"):
        bpy.ops.fraccloth.bake()
    assert cloth.modifiers.get("fraccloth") is None
