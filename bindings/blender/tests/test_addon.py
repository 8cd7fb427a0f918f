"""The add-on in real Blender (the `bpy` module): enable it headless, bake a small scene, read
the evaluated mesh back at several frames and compare it with the library's own positions.

Run with a Python that has `bpy` and the `fraccloth` package installed (see .ci/blender).
"""

import math
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
    assert hasattr(bpy.types.Object, "fraccloth")
    yield mod
    addon_utils.disable("fraccloth_blender")


def make_scene(tmp_path, fmt, k=1.0):
    """The test scene; `k` Blender units to the metre (every length `k` times larger)."""
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
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=12, y_subdivisions=8, size=0.3 * k,
                                    location=(0.1 * k, -0.2 * k, 0.2 * k), rotation=(0.0, 0.0, 0.3))
    cloth = bpy.context.active_object
    group = cloth.vertex_groups.new(name="pins")
    ys = [v.co.y for v in cloth.data.vertices]
    edge = [v.index for v in cloth.data.vertices if v.co.y > max(ys) - 1e-6]
    group.add(edge, 1.0, "REPLACE")
    # A ball under the middle of the cloth and a floor.
    bpy.ops.mesh.primitive_uv_sphere_add(radius=0.05 * k, location=(0.1 * k, -0.2 * k, 0.1 * k))
    ball = bpy.context.active_object
    bpy.ops.mesh.primitive_plane_add(size=2.0 * k, location=(0.0, 0.0, -0.1 * k))
    floor = bpy.context.active_object
    for o in (ball, floor):
        o.select_set(True)
    cloth.select_set(True)
    bpy.context.view_layer.objects.active = cloth
    s = cloth.fraccloth
    s.cache_format = fmt
    s.cache_path = str(tmp_path / "cloth")
    s.integrator = "SYMPLECTIC"
    s.auto_step = False
    s.time_step = 1e-3
    s.current = (0.05, 0.0, 0.0)
    s.friction = 0.2
    # These tests are of the fitted shapes (a mesh collider test follows at the end).
    s.collider_shape = "FITTED"
    return cloth, [ball, floor]


def evaluated(obj, frame):
    bpy.context.scene.frame_set(frame)
    deps = bpy.context.evaluated_depsgraph_get()
    me = obj.evaluated_get(deps).to_mesh()
    co = np.empty(3 * len(me.vertices), dtype=np.float32)
    me.vertices.foreach_get("co", co)
    obj.evaluated_get(deps).to_mesh_clear()
    return co.reshape(-1, 3)


@pytest.mark.parametrize("fmt,auto", [("PC2", False), ("MDD", False), ("PC2", True)])
def test_bake_reads_back_exactly(addon, tmp_path, fmt, auto):
    cloth, others = make_scene(tmp_path, fmt)
    # The library's automatic step (FC_MAX_SUBSTEP_AUTO) or the panel's fixed 1 ms.
    cloth.fraccloth.auto_step = auto
    rest = np.array([v.co[:] for v in cloth.data.vertices], dtype=np.float32)
    result = bpy.ops.fraccloth.bake()
    assert result == {"FINISHED"}
    mod = cloth.modifiers.get("fraccloth")
    assert mod is not None and mod.type == "MESH_CACHE" and mod.cache_format == fmt
    assert Path(mod.filepath).exists()
    # The library's own positions: the add-on's simulation, run again with the same inputs.
    expected = {f: local for f, _, local in addon.simulate(bpy.context, cloth, others)}
    for frame in (1, 2, 12, 24):
        got = evaluated(cloth, frame)
        assert got.shape == expected[frame].shape
        assert np.array_equal(got, expected[frame]), f"frame {frame}: max diff {np.abs(got - expected[frame]).max()}"
    # It moved: the free edge sagged, the pinned edge stayed.
    last = expected[24]
    assert np.abs(last - rest).max() > 0.01
    pinned = [v.index for v in cloth.data.vertices if v.groups]
    assert np.allclose(last[pinned], rest[pinned], atol=1e-6)


def world(obj, frame):
    """Evaluated vertex positions in world coordinates at `frame`."""
    local = evaluated(obj, frame).astype(np.float64)
    m = np.array(obj.matrix_world, dtype=np.float64)
    return local @ m[:3, :3].T + m[:3, 3]


def test_pins_follow_an_animated_object_and_the_cloth_lags(addon, tmp_path):
    # The cloth object moves 0.2 m along x over the first second, then stops: the pinned
    # vertices go with it (the pins follow the evaluated mesh in world space), the free part
    # trails behind in the water while the object moves.
    def bake(animated):
        cloth, _ = make_scene(tmp_path, "PC2")
        cloth.fraccloth.cache_path = str(tmp_path / ("moving" if animated else "still"))
        if animated:
            cloth.location = (0.1, -0.2, 0.2)
            cloth.keyframe_insert("location", frame=1)
            cloth.location = (0.3, -0.2, 0.2)
            cloth.keyframe_insert("location", frame=24)
        assert bpy.ops.fraccloth.bake() == {"FINISHED"}
        pinned = [v.index for v in cloth.data.vertices if v.groups]
        rest = np.array([v.co[:] for v in cloth.data.vertices], dtype=np.float64)
        m = np.array(cloth.matrix_world, dtype=np.float64)
        return cloth, pinned, rest, evaluated(cloth, 12).astype(np.float64), m

    _, _, _, still, _ = bake(False)
    cloth, pinned, rest, moving, _ = bake(True)
    # Pinned vertices sit where the animated object puts them (local = rest at every frame).
    for frame in (6, 12, 24):
        got = evaluated(cloth, frame)
        assert np.allclose(got[pinned], rest[pinned], atol=1e-5), frame
    # Mid-move, the free vertices trail: in the object's frame they sit behind (-x, the frame's
    # own axis is turned by 0.3 rad) where they hang when nothing moves.
    free = [i for i in range(len(rest)) if i not in set(pinned)]
    lag = (moving[free] - still[free]).mean(axis=0)
    back = np.array([-np.cos(0.3), np.sin(0.3), 0.0])
    assert lag @ back > 0.005, f"free part did not trail: {lag}"


def rising_ball_pushes(cloth, ball):
    """Keyframes the ball rising from under the hanging cloth up through where it hangs, bakes,
    and checks that no cloth vertex gets deeper into it than the collision margin and that it
    did reach the cloth (the check could not pass by missing it)."""
    ball.location = (0.1, -0.2, -0.15)
    ball.keyframe_insert("location", frame=1)
    ball.location = (0.1, -0.2, 0.35)
    ball.keyframe_insert("location", frame=24)
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}
    margin, radius = 0.01, 0.05
    closest = np.inf
    for frame in range(1, 25):
        x = world(cloth, frame)
        bpy.context.scene.frame_set(frame)
        c = np.array(ball.matrix_world.translation)
        d = np.linalg.norm(x - c, axis=1)
        assert d.min() >= radius - margin - 1e-4, f"frame {frame}: a vertex {radius - d.min():.4f} m inside"
        closest = min(closest, d.min())
    assert closest < radius + margin, closest


def test_an_animated_sphere_pushes_the_cloth_and_never_enters_it(addon, tmp_path):
    cloth, others = make_scene(tmp_path, "PC2")
    rising_ball_pushes(cloth, others[0])


def test_bad_input_is_reported_not_crashed(addon, tmp_path):
    cloth, _ = make_scene(tmp_path, "PC2")
    cloth.scale = (2.0, 1.0, 1.0)
    bpy.context.view_layer.update()
    with pytest.raises(RuntimeError, match="apply its scale"):
        bpy.ops.fraccloth.bake()
    assert cloth.modifiers.get("fraccloth") is None


def test_the_underwater_preset_is_the_librarys(addon, tmp_path):
    import fraccloth

    cloth, _ = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    s.preset = "UNDERWATER"
    got = addon.describe(s)
    want = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    for field in ("stretch_stiffness", "shear_stiffness", "bend_stiffness", "bend_reference_spacing", "spring_damping", "spring_damping_mode",
                  "entrained_mass", "added_mass", "coarse_added_mass", "coarse_length", "form_drag", "form_drag_scale",
                  "skin_drag", "skin_drag_unsteady", "skin_drag_memory", "cloth_density", "water_density",
                  "integrator", "viscous_drag", "history_drag", "normal_drag", "viscous_drag_per_area",
                  "history_drag_per_area", "normal_drag_per_area"):
        assert getattr(got, field) == pytest.approx(getattr(want, field), rel=1e-6), field
    # The other presets differ from it visibly (weight and stiffness), and CUSTOM changes nothing.
    s.preset = "SILK"
    assert s.mass_per_area < 0.5 and s.bend_stiffness < 0.1
    s.preset = "CUSTOM"
    assert s.mass_per_area < 0.5
    # The automatic step is the library's: the bake asks for FC_MAX_SUBSTEP_AUTO.
    s.preset = "UNDERWATER"
    s.auto_step = True
    built, (frame_dt, substeps), _, _ = addon.build_cloth(bpy.context, cloth, [])
    assert substeps is None and built.desc.max_substep == fraccloth.MAX_SUBSTEP_AUTO


def test_the_water_at_large_reaches_the_library_and_a_bad_patch_size_is_refused(addon, tmp_path):
    """The panel's large-scale added mass and patch size are the library's `coarse_added_mass`
    and `coarse_length`; the water carried at large slows the towel's fall face first; a patch
    size that makes too many patches is refused with the library's reason and no cache."""
    cloth, others = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    assert s.coarse_added_mass == 0.0 and addon.describe(s).coarse_length == 0.0
    s.coarse_added_mass, s.coarse_length = 100.0, 0.1
    d = addon.describe(s)
    assert d.coarse_added_mass == pytest.approx(100.0) and d.coarse_length == pytest.approx(0.1)
    rest = np.array([v.co[:] for v in cloth.data.vertices], dtype=np.float64)

    def sag(mass):
        s.coarse_added_mass = mass
        frames = {f: local for f, _, local in addon.simulate(bpy.context, cloth, others)}
        return np.abs(frames[6].astype(np.float64) - rest).max()

    with_water, without = sag(100.0), sag(0.0)
    assert 0.0 < with_water < 0.8 * without, (with_water, without)
    s.coarse_added_mass = 100.0
    s.coarse_length = 0.001
    with pytest.raises(RuntimeError, match="at most 256 patches: use a coarse_length of at least"):
        bpy.ops.fraccloth.bake()
    assert not Path(str(tmp_path / "cloth") + ".pc2").exists()
    assert cloth.modifiers.get("fraccloth") is None


def test_two_cloths_bake_to_their_own_caches(addon, tmp_path):
    first, _ = make_scene(tmp_path, "PC2")
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=6, y_subdivisions=4, size=0.2, location=(1.0, 0.0, 0.3))
    second = bpy.context.active_object
    second.name = "Second towel"
    second.fraccloth.pin_group = ""  # no pins: it falls
    for o in bpy.context.selected_objects:
        o.select_set(False)
    results = []
    for obj in (first, second):
        obj.fraccloth.cache_path = ""  # the default: next to the .blend (here: Blender's temp folder)
        obj.fraccloth.preset = "UNDERWATER"
        obj.select_set(True)
        bpy.context.view_layer.objects.active = obj
        results.append(bpy.ops.fraccloth.bake())
        obj.select_set(False)
    assert results == [{"FINISHED"}, {"FINISHED"}]
    paths = [Path(o.modifiers["fraccloth"].filepath) for o in (first, second)]
    assert paths[0] != paths[1] and all(p.exists() for p in paths)
    assert paths[1].stem == "Second_towel"


def test_a_cancelled_bake_leaves_no_cache(addon, tmp_path):
    # The job the interface's modal bake runs a frame per timer tick, cancelled half-way (what Esc
    # does): no cache file, no modifier, the scene back at its frame.
    cloth, others = make_scene(tmp_path, "PC2")
    scene = bpy.context.scene
    scene.frame_set(5)
    job = addon.BakeJob(bpy.context, cloth, others)
    for _ in range(10):
        assert job.step() is False
    assert Path(job.partial).exists() and not Path(job.path).exists()  # partly written, aside
    job.cancel()
    assert not Path(job.partial).exists() and not Path(job.path).exists()
    assert cloth.modifiers.get("fraccloth") is None
    assert scene.frame_current == 5
    # Run to the end, the same job attaches a complete cache.
    job = addon.BakeJob(bpy.context, cloth, others)
    while not job.step():
        pass
    assert job.done == 24 and Path(job.path).exists()
    assert cloth.modifiers.get("fraccloth") is not None and scene.frame_current == 5


def test_a_failed_bake_reports_and_leaves_no_cache(addon, tmp_path):
    cloth, _ = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    s.auto_step = False
    s.integrator = "EXPLICIT"
    s.time_step = 0.05  # far above explicit Euler's bound: a step is refused
    with pytest.raises(RuntimeError, match="unstable"):
        bpy.ops.fraccloth.bake()
    assert not Path(str(tmp_path / "cloth") + ".pc2").exists()
    assert cloth.modifiers.get("fraccloth") is None


def test_a_long_object_is_a_capsule_that_holds_the_cloth(addon, tmp_path):
    # A bar (a cylinder 0.5 m long, 6 cm thick) parallel to the pinned edge under the middle of
    # the cloth, rising through where the cloth falls: it is fitted as a capsule, and it lifts the
    # cloth without passing through it.
    cloth, _ = make_scene(tmp_path, "PC2")
    edge = np.array([math.cos(0.3), math.sin(0.3), 0.0])  # the pinned edge's direction
    inward = np.array([math.sin(0.3), -math.cos(0.3), 0.0])  # from the edge into the cloth
    hinge = np.array([0.1, -0.2, 0.2]) - 0.15 * inward
    centre = hinge + 0.15 * inward + np.array([0.0, 0.0, -0.1])
    bpy.ops.mesh.primitive_cylinder_add(radius=0.03, depth=0.5, location=tuple(centre), rotation=(0.0, math.pi / 2, 0.3))
    bar = bpy.context.active_object
    specs = addon._world_specs([bar])
    assert specs[0][0] == "capsule"
    a, b, r = np.array(specs[0][1]), np.array(specs[0][2]), specs[0][3]
    assert r == pytest.approx(0.03, rel=1e-3) and np.linalg.norm(b - a) == pytest.approx(0.44, rel=1e-3)
    assert abs((b - a) @ edge) > 0.43  # along the edge
    bar.keyframe_insert("location", frame=1)
    bar.location.z = 0.35
    bar.keyframe_insert("location", frame=24)
    bpy.context.scene.frame_set(1)
    for o in bpy.context.selected_objects:
        o.select_set(False)
    bar.select_set(True)
    cloth.select_set(True)
    bpy.context.view_layer.objects.active = cloth
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}
    margin = cloth.fraccloth.collision_margin
    closest = np.inf
    for frame in range(1, 25):
        x = world(cloth, frame)
        spec = addon._world_specs([bar])[0]
        a, b = np.array(spec[1]), np.array(spec[2])
        # Distance to the segment a-b.
        t = np.clip(((x - a) @ (b - a)) / ((b - a) @ (b - a)), 0.0, 1.0)
        d = np.linalg.norm(x - (a + t[:, None] * (b - a)), axis=1)
        assert d.min() >= r - margin - 1e-4, f"frame {frame}: {r - d.min():.4f} m inside the bar"
        closest = min(closest, d.min())
    assert closest < r + margin, closest  # it did reach the bar (contacts act at the vertices)


def test_a_self_collision_in_spacings_is_resolved_by_the_meshs_spacing(addon, tmp_path):
    """The panel's "Self-collision (spacings)" reaches the library, which turns it into metres
    by the mesh's spacing (the side of a square of two of its triangles' mean area: here the
    quads' mean area), added to the thickness in metres."""
    cloth, _ = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    s.self_collision, s.self_collision_spacings = 0.001, 0.4
    assert addon.describe(s).self_collision_relative == pytest.approx(0.4)
    built, _, _, _ = addon.build_cloth(bpy.context, cloth, [])
    quads = cloth.data.polygons
    spacing = (sum(p.area for p in quads) / len(quads)) ** 0.5
    got = built.desc
    assert got.self_collision_relative == 0.0
    assert got.self_collision_thickness == pytest.approx(0.001 + 0.4 * spacing, rel=1e-3)


def test_an_armature_animated_mesh_collider_pushes_the_cloth(addon, tmp_path):
    """A box skinned to a bone, the bone animated (the object itself never moves): the add-on
    reads the evaluated mesh every frame, the box rises through where the cloth hangs, pushes it
    and no cloth vertex is ever inside it."""
    cloth, _ = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    s.collider_shape = "MESH"
    s.self_collision = 0.004
    s.auto_step = True
    bpy.ops.object.armature_add(location=(0.1, -0.25, -0.25))
    arm = bpy.context.active_object
    bpy.ops.mesh.primitive_cube_add(size=0.1, location=(0.1, -0.25, -0.25))
    box = bpy.context.active_object
    mod = box.modifiers.new("skin", "ARMATURE")
    mod.object = arm
    box.vertex_groups.new(name="Bone").add(list(range(len(box.data.vertices))), 1.0, "REPLACE")
    bone = arm.pose.bones["Bone"]
    bone.location = (0.0, 0.0, 0.0)
    bone.keyframe_insert("location", frame=1)
    bone.location = (0.0, 0.5, 0.0)  # along the bone, world +z: 0.5 m up
    bone.keyframe_insert("location", frame=24)
    bpy.context.scene.frame_set(1)
    for o in bpy.context.selected_objects:
        o.select_set(False)
    box.select_set(True)
    cloth.select_set(True)
    bpy.context.view_layer.objects.active = cloth
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}
    margin = s.collision_margin
    closest, rose = np.inf, 0.0
    for frame in range(1, 25):
        x = world(cloth, frame)
        bpy.context.scene.frame_set(frame)
        corners = addon._mesh_spec(box)[1]
        lo, hi = corners.min(axis=0), corners.max(axis=0)
        assert box.matrix_world.translation.z == pytest.approx(-0.25)  # only the bone moved
        # Outside-the-box distance of each vertex (negative inside).
        d = np.maximum(lo - x, x - hi).max(axis=1)
        assert d.min() > 0.0, f"frame {frame}: a cloth vertex {-d.min():.4f} m inside the box"
        closest = min(closest, d.min())
        rose = max(rose, x[:, 2].max())
    assert closest < margin + 1e-3, f"the box never reached the cloth: {closest}"
    assert lo[2] > 0.19 and rose > 0.2 + 0.05, f"the box lifted the cloth above its rest height: {rose}"


def test_a_refused_rebake_keeps_the_good_bake(addon, tmp_path):
    """After a good bake, a Subdivision modifier makes the setup invalid: the re-bake is refused
    with the reason, and the first bake's modifier and cache file are still there."""
    cloth, _ = make_scene(tmp_path, "PC2")
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}
    path = Path(cloth.modifiers["fraccloth"].filepath)
    before = path.read_bytes()
    sub = cloth.modifiers.new("sub", "SUBSURF")
    with pytest.raises(RuntimeError, match="vertex count"):
        bpy.ops.fraccloth.bake()
    assert cloth.modifiers.get("fraccloth") is not None
    assert path.exists() and path.read_bytes() == before
    assert not Path(str(path) + ".baking").exists()
    cloth.modifiers.remove(sub)


def test_select_all_leaves_camera_and_light_out(addon, tmp_path):
    """Select-all with a camera and a light in the scene: they are not colliders, the bake works."""
    cloth, others = make_scene(tmp_path, "PC2")
    bpy.ops.object.camera_add(location=(0.0, -1.0, 0.3))
    bpy.ops.object.light_add(type="POINT", location=(0.5, 0.5, 1.0))
    for o in bpy.context.scene.objects:
        o.select_set(True)
    bpy.context.view_layer.objects.active = cloth
    selected = [o for o in bpy.context.selected_objects if o is not cloth]
    assert len(addon._world_specs(selected)) == len(others)
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}


def test_a_missing_pin_group_is_an_error(addon, tmp_path):
    cloth, _ = make_scene(tmp_path, "PC2")
    cloth.fraccloth.pin_group = "pinz"
    with pytest.raises(RuntimeError, match="no vertex group named 'pinz'.*pins"):
        bpy.ops.fraccloth.bake()
    assert cloth.modifiers.get("fraccloth") is None


def test_a_new_cloth_starts_on_the_librarys_underwater_towel_and_edits_say_custom(addon, tmp_path):
    """A new object's settings are the library's FC_PRESET_UNDERWATER, labelled so; changing a
    value relabels it Custom; fractional damping with the history Off is refused with the reason."""
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=4, y_subdivisions=4, size=0.1)
    fresh = bpy.context.active_object.fraccloth
    assert fresh.preset == "UNDERWATER"
    for name, value in addon._library_preset().items():
        got = getattr(fresh, name)
        assert got == (pytest.approx(value, rel=1e-6) if isinstance(value, float) else value), name
    fresh.bend_stiffness = 1.0
    assert fresh.preset == "CUSTOM"
    fresh.preset = "SILK"
    assert fresh.preset == "SILK" and fresh.mass_per_area < 0.5
    cloth, _ = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    s.damping_mode, s.spring_damping, s.history = "FRACTIONAL", 0.35, "OFF"
    with pytest.raises(RuntimeError, match="needs a History"):
        bpy.ops.fraccloth.bake()


def test_free_bake_removes_the_modifier_and_its_file(addon, tmp_path):
    cloth, _ = make_scene(tmp_path, "PC2")
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}
    path = Path(cloth.modifiers["fraccloth"].filepath)
    assert path.exists()
    assert bpy.ops.fraccloth.free_bake() == {"FINISHED"}
    assert cloth.modifiers.get("fraccloth") is None
    assert not path.exists()
    # Nothing left to free: the button is greyed out.
    assert not bpy.ops.fraccloth.free_bake.poll()


def test_a_frame_range_of_its_own(addon, tmp_path):
    """Off the scene's range, the bake covers its own frames: the cache starts at its first
    frame (the rest state) and plays the library's positions at its last."""
    cloth, others = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    s.use_scene_range, s.frame_start, s.frame_end = False, 5, 12
    rest = np.array([v.co[:] for v in cloth.data.vertices], dtype=np.float32)
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}
    mod = cloth.modifiers["fraccloth"]
    assert mod.frame_start == 5.0
    expected = {f: local for f, _, local in addon.simulate(bpy.context, cloth, others)}
    assert sorted(expected) == list(range(5, 13))
    assert np.array_equal(evaluated(cloth, 5), expected[5])
    assert np.allclose(expected[5], rest, atol=1e-6)
    assert np.array_equal(evaluated(cloth, 12), expected[12])
    assert np.abs(expected[12] - rest).max() > 0.002
    s.frame_start, s.frame_end = 12, 5
    with pytest.raises(RuntimeError, match="ends .* before it starts"):
        bpy.ops.fraccloth.bake()


def test_the_scenes_gravity_is_the_clothes(addon, tmp_path):
    """With the scene's gravity off, a free cloth in still water has neither weight nor
    buoyancy: it stays where it is."""
    cloth, _ = make_scene(tmp_path, "PC2")
    s = cloth.fraccloth
    s.pin_group, s.current = "", (0.0, 0.0, 0.0)
    bpy.context.scene.use_gravity = False
    try:
        rest = world(cloth, 1)
        assert bpy.ops.fraccloth.bake() == {"FINISHED"}
        assert np.abs(world(cloth, 24) - rest).max() < 1e-5
    finally:
        bpy.context.scene.use_gravity = True


def test_the_unit_scale_gives_the_same_motion_in_metres(addon, tmp_path):
    """The same scene built twice as large in Blender units with a unit scale of 0.5 m (and its
    gravity given in those units) bakes the same motion in metres."""
    scene = bpy.context.scene
    cloth, _ = make_scene(tmp_path / "one", "PC2")
    assert bpy.ops.fraccloth.bake() == {"FINISHED"}
    metres = world(cloth, 24)
    try:
        scene.unit_settings.scale_length = 0.5
        scene.gravity = (0.0, 0.0, -9.81 / 0.5)
        cloth, _ = make_scene(tmp_path / "two", "PC2", k=2.0)
        assert bpy.ops.fraccloth.bake() == {"FINISHED"}
        scaled = world(cloth, 24) * 0.5
    finally:
        scene.unit_settings.scale_length = 1.0
        scene.gravity = (0.0, 0.0, -9.81)
    assert np.abs(metres - world(cloth, 1) * 0.5).max() > 0.01  # it moved
    assert np.abs(scaled - metres).max() < 1e-4, np.abs(scaled - metres).max()


def test_an_object_with_collision_physics_collides_unselected(addon, tmp_path):
    """Colliders are chosen as Blender's cloth chooses them: a mesh with Collision physics
    pushes the cloth without being selected."""
    cloth, others = make_scene(tmp_path, "PC2")
    ball, floor = others
    for o in others:
        o.select_set(False)
    ball.modifiers.new("Collision", "COLLISION")
    assert addon.colliders_of(bpy.context, cloth) == [ball]
    rising_ball_pushes(cloth, ball)


def test_a_collider_with_its_own_friction_grips_with_it(addon, tmp_path, monkeypatch):
    """Per-object collision settings: a collider's own friction and margin ("As a collider: Own
    friction", "Own margin") replace the cloth's for that collider only."""
    import fraccloth

    cloth, others = make_scene(tmp_path, "PC2")
    ball, floor = others
    s = cloth.fraccloth
    s.friction = 0.1
    ball.fraccloth.collider_own_friction = True
    ball.fraccloth.collider_friction = 0.7
    assert addon.collider_friction_of(s, ball) == pytest.approx(0.7)
    assert addon.collider_friction_of(s, floor) == pytest.approx(0.1)
    calls = []
    real = fraccloth.Cloth.set_collider_friction

    def spy(self, cid, friction):
        calls.append(friction)
        return real(self, cid, friction)

    monkeypatch.setattr(fraccloth.Cloth, "set_collider_friction", spy)
    ball.fraccloth.collider_own_margin = True
    ball.fraccloth.collider_margin = 0.025
    for shape in ("MESH", "FITTED"):
        s.collider_shape = shape
        calls.clear()
        objects = addon.collider_objects(s, others)
        built, _, _, ids = addon.build_cloth(bpy.context, cloth, others)
        want = [0.7 if o is ball else 0.1 for o in objects]
        assert calls == pytest.approx(want), shape
        # The ball keeps the cloth at its own margin, the floor at the cloth's.
        margins = [built.collider_margin(i) for i in ids]
        assert margins == pytest.approx([0.025 if o is ball else s.collision_margin for o in objects], rel=1e-5)
