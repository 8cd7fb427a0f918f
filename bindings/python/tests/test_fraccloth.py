"""Tests of the Python bindings: against the C example's output, numpy round trips, errors,
meshes, colliders and caches."""

import ctypes
import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fraccloth

REPO = Path(__file__).resolve().parents[3]


def lib_dir() -> Path:
    return Path(fraccloth.library._name).parent


def compile_c(source: str, tmp_path: Path) -> Path:
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    exe = tmp_path / Path(source).stem
    header_dir = tmp_path / "include"
    header_dir.mkdir(exist_ok=True)
    # The header packaged with the library (identical to include/fraccloth.h).
    shutil.copy2(lib_dir() / "fraccloth.h" if (lib_dir() / "fraccloth.h").exists() else REPO / "include" / "fraccloth.h",
                 header_dir / "fraccloth.h")
    # The library's SONAME is libfraccloth.so.MAJOR: give the loader that name beside the program.
    lib = tmp_path / "libfraccloth.so"
    if not lib.exists():
        lib.symlink_to(Path(fraccloth.library._name).resolve())
    soname = tmp_path / f"libfraccloth.so.{fraccloth.version().split('.')[0]}"
    if not soname.exists():
        soname.symlink_to(lib.name)
    subprocess.run(
        [cc, "-std=c99", "-Wall", "-Wextra", "-Werror", "-I", str(header_dir), str(REPO / "examples_c" / source),
         "-o", str(exe), str(lib), f"-Wl,-rpath,{lib.parent}", "-lm"],
        check=True,
    )
    return exe


def test_hello_matches_the_c_example(tmp_path):
    out = subprocess.run([str(compile_c("hello.c", tmp_path))], check=True, capture_output=True, text=True).stdout
    corner = next(l for l in out.splitlines() if l.startswith("corner")).split()
    desc = fraccloth.default_desc()
    with fraccloth.Cloth.grid(desc) as cloth:
        cloth.set_pinned(range(desc.width))
        for _ in range(2000):
            cloth.step(5e-4)
        x = cloth.positions
    k = int(corner[1])
    assert k == cloth_vertex_count(desc) - desc.width
    # The C program prints with %.9g: parsing gives back the float exactly.
    assert [np.float32(v) for v in corner[2:5]] == list(x[k])


def cloth_vertex_count(desc) -> int:
    return desc.width * desc.height


def test_swing_pc2_matches_the_c_example(tmp_path):
    """examples_c/swing.c bakes the paper's swing to PC2; the same loop from Python
    (mirrored line by line below) gives the same floats."""
    exe = compile_c("swing.c", tmp_path)
    pc2 = tmp_path / "swing.pc2"
    subprocess.run([str(exe), str(pc2), "1.0"], check=True, capture_output=True)
    data = pc2.read_bytes()
    n = int(np.frombuffer(data[16:20], "<i4")[0])
    frames = int(np.frombuffer(data[28:32], "<i4")[0])
    c_frames = np.frombuffer(data[32:], "<f4").reshape(frames, n, 3)

    amplitude, frequency, dt, fps, seconds = 0.08, 0.5, 5e-4, 30, 1.0
    desc = fraccloth.preset_desc(fraccloth.PRESET_FRACTIONAL_PAPER)
    mine = []
    with fraccloth.Cloth.grid(desc) as cloth:
        w = desc.width
        top = np.arange(w)
        rest = cloth.positions[:w].copy()
        cloth.set_pinned(top)
        steps = round(seconds / dt)
        k = 0
        for s in range(steps + 1):
            if s == round(k / (fps * dt)):
                mine.append(cloth.positions)
                k += 1
            if s == steps:
                break
            z = amplitude * np.sin(2.0 * 3.14159265358979323846 * frequency * (s + 1) * dt)
            target = rest.copy()
            target[:, 2] = rest[:, 2] + np.float32(z)
            cloth.set_pin_targets(top, target)
            cloth.step(dt)
    assert len(mine) == frames
    assert np.array_equal(np.array(mine), c_frames)


def test_second_order_integrators_strain_springs_and_exact_state():
    desc = fraccloth.preset_desc(fraccloth.PRESET_FRACTIONAL_PAPER)
    desc.width, desc.height = 11, 7
    desc.integrator = fraccloth.INTEGRATOR_EXTRAPOLATED_IMPLICIT
    desc.spring_damping_mode = fraccloth.SPRING_DAMPING_FRACTIONAL_STRAIN
    desc.history_scheme = fraccloth.HISTORY_SOE
    with fraccloth.Cloth.grid(desc) as cloth:
        x = cloth.positions_f64()
        assert x.dtype == np.float64 and x.shape == (77, 3)
        moved = x + 1e-9  # below float32's resolution at these coordinates
        cloth.set_positions_f64(moved)
        assert np.array_equal(cloth.positions_f64(), moved)
        v = np.full((77, 3), 0.01)
        cloth.velocities = v
        assert np.array_equal(cloth.velocities_f64(), v)
        cloth.set_pinned(range(11))
        for _ in range(10):
            cloth.step(1.0 / 60.0)
        assert np.isfinite(cloth.positions_f64()).all()
        with pytest.raises(fraccloth.Error):
            cloth.velocities = np.full((77, 3), np.nan)
        ball = cloth.add_sphere([0.0, -0.1, 0.2], 0.05)
        centre, radius = cloth.sphere(ball)
        assert np.allclose(centre, [0.0, -0.1, 0.2]) and radius == pytest.approx(0.05)
        wall = cloth.add_plane([0.0, -1.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.1, 0.0])
        point, normal, velocity = cloth.plane(wall)
        assert np.allclose(normal, [0.0, 1.0, 0.0]) and np.allclose(velocity, [0.0, 0.1, 0.0])
        rod = cloth.add_capsule([0.0, 0.0, 0.1], [0.1, 0.0, 0.1], 0.01)
        a, b, r, v = cloth.capsule(rod)
        assert np.allclose(b, [0.1, 0.0, 0.1]) and r == pytest.approx(0.01)
        with pytest.raises(fraccloth.Error):
            cloth.capsule(wall)
        d = cloth.desc
        assert d.width == 11 and d.spring_damping_mode == fraccloth.SPRING_DAMPING_FRACTIONAL_STRAIN
        d.stretch_stiffness = 20.0
        cloth.desc = d
        assert cloth.desc.stretch_stiffness == 20.0
        d.history_scheme = fraccloth.HISTORY_FULL
        with pytest.raises(fraccloth.Error):
            cloth.desc = d
        tris = cloth.triangles()
        assert tris.shape == (2 * 10 * 6, 3) and tris.max() == 76
        n = cloth.normals
        assert n.shape == (77, 3) and np.allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-6)


def test_a_misspelt_description_field_raises():
    d = fraccloth.default_desc()
    with pytest.raises(AttributeError):
        d.sping_damping = 0.5
    d.spring_damping = 0.5
    assert d.spring_damping == 0.5


def test_errors_raise_and_leave_the_cloth_alone():
    with fraccloth.Cloth.grid() as cloth:
        before = cloth.positions
        with pytest.raises(fraccloth.Error) as e:
            cloth.step(-1.0)
        assert e.value.status == 2 and "dt" in e.value.message
        with pytest.raises(fraccloth.Error) as e:
            cloth.set_pinned([10**6])
        assert e.value.status == 3
        assert np.array_equal(cloth.positions, before)
        with pytest.raises(ValueError):
            cloth.set_current([1.0, 2.0])


def test_mesh_colliders_and_caches(tmp_path):
    w, h = 9, 7
    xs, ys = np.meshgrid(np.arange(w) * 0.02, -np.arange(h) * 0.02)
    pos = np.stack([xs.ravel(), ys.ravel(), np.zeros(w * h)], axis=1)
    quads = [[j * w + i, (j + 1) * w + i, (j + 1) * w + i + 1, j * w + i + 1] for j in range(h - 1) for i in range(w - 1)]
    with fraccloth.Cloth.mesh(None, pos, quads) as cloth:
        assert cloth.vertex_count == w * h
        cloth.pin_group(range(w), 1.0)
        cloth.set_current([0.0, 0.0, 0.2])
        plane = cloth.add_plane([0, -0.2, 0], [0, 1, 0])
        cap = cloth.add_capsule([0, -0.1, 0.05], [0.2, -0.1, 0.05], 0.02)
        cloth.set_collider_friction(cap, 0.4)
        cloth.remove_collider(plane)
        mdd = tmp_path / "m.mdd"
        with fraccloth.Cache(mdd, fraccloth.CACHE_MDD, cloth, 1.0, 24.0, expected_frames=3) as cache:
            frames = []
            for _ in range(3):
                for _ in range(20):
                    cloth.step(1e-3)
                cache.write_frame(cloth)
                frames.append(cloth.positions)
        data = mdd.read_bytes()
        assert np.frombuffer(data[:8], ">i4").tolist() == [3, w * h]
        assert np.array_equal(np.frombuffer(data[20:], ">f4").reshape(3, w * h, 3), np.array(frames))
    with pytest.raises(fraccloth.Error) as e:
        fraccloth.Cloth.mesh(None, pos, [[0, 1, 99]])
    assert e.value.status == 3 and "99" in e.value.message


def test_description_layout_matches_the_library():
    d = fraccloth.default_desc()
    assert (d.width, d.height) == (61, 41)
    assert d.history_scheme == fraccloth.HISTORY_SOE
    p = fraccloth.preset_desc(fraccloth.PRESET_FRACTIONAL_PAPER)
    assert (p.history_scheme, p.history_u) == (fraccloth.HISTORY_TRUNCATED, 3)
    assert fraccloth.version().count(".") == 2


def test_generated_abi_matches_the_header():
    script = REPO / "scripts" / "gen_python_abi.py"
    if not script.exists():
        pytest.skip("not in the repository")
    subprocess.run([sys.executable, str(script), "--check"], check=True)


def test_the_package_parses_as_python_3_8():
    import ast

    for path in Path(fraccloth.__file__).parent.glob("*.py"):
        ast.parse(path.read_text(), filename=str(path), feature_version=(3, 8))


def test_a_description_without_struct_size_is_refused_with_a_message():
    d = fraccloth.FcClothDesc()  # all zero: not from default_desc()
    with pytest.raises(fraccloth.Error) as e:
        fraccloth.Cloth.grid(d)
    assert "struct_size" in e.value.message
    assert fraccloth.default_desc().struct_size == ctypes.sizeof(fraccloth.FcClothDesc)


def test_snapshots_threads_and_solver():
    desc = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    desc.width, desc.height, desc.spacing = 15, 11, 0.02
    with fraccloth.Cloth.grid(desc) as cloth:
        cloth.set_pinned(range(15))
        cloth.threads = 1
        assert cloth.threads == 1
        cloth.set_current([0.0, 0.0, 0.1])
        assert list(cloth.desc.current) == [0.0, 0.0, 0.1]
        cloth.step(1e-3)
        snap = cloth.save_snapshot()
        cloth.step(1e-3)
        after = cloth.positions_f64()
        cloth.load_snapshot(snap)
        cloth.step(1e-3)
        assert np.array_equal(cloth.positions_f64(), after)
        with pytest.raises(fraccloth.Error):
            cloth.load_snapshot(snap[:-1])
        d = cloth.desc
        d.integrator = fraccloth.INTEGRATOR_IMPLICIT_EULER
        cloth.desc = d
        cloth.set_solver(1e-8, 300)
        cloth.set_solver_accept_unconverged(False)
        cloth.step(1.0 / 60.0)
        stats = cloth.solver_stats()
        assert stats.iterations > 0 and stats.residual <= 1e-8
        assert cloth.triangle_count == cloth.triangles().shape[0] == 2 * 14 * 10
        assert cloth.history_bytes_per_particle == 0


def test_every_call_of_the_header_is_bound():
    header = REPO / "include" / "fraccloth.h"
    if not header.exists():
        pytest.skip("not in the repository")
    import re

    calls = set(re.findall(r"\b(fc_[a-z0-9_]+)\(", header.read_text()))
    # The header's inline wrappers; the package calls what they call (the sized variants).
    inline = {"fc_cloth_desc_default", "fc_cloth_desc_preset", "fc_cloth_get_desc"}
    missing = sorted(calls - inline - set(fraccloth._SIGNATURES))
    assert not missing, f"C calls the Python package does not bind: {missing}"


def test_the_underwater_preset_steps_once_per_frame_with_the_automatic_step():
    desc = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    assert desc.max_substep == fraccloth.MAX_SUBSTEP_AUTO
    desc.width, desc.height, desc.spacing = 21, 15, 0.02
    with fraccloth.Cloth.grid(desc) as cloth:
        cloth.set_pinned(np.arange(21))
        for _ in range(10):
            cloth.step(1 / 30)
        stats = cloth.step_stats()
        assert stats.substeps >= 2 and stats.retries == 0 and 0 < stats.estimate < 1 / 30
        # A fixed step keeps its count: 1/30 s in 1 ms substeps.
        d = cloth.desc
        d.max_substep = 1e-3
        cloth.desc = d
        cloth.step(1 / 30)
        assert cloth.step_stats() == fraccloth.StepStats(34, 0, 0.0)


def test_self_collision_thickness_in_spacings():
    """A thickness given in spacings comes back in metres: 0.25 of a 2 cm grid is 5 mm."""
    desc = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    desc.width, desc.height, desc.spacing = 21, 21, 0.02
    desc.self_collision_relative = 0.25
    with fraccloth.Cloth.grid(desc) as cloth:
        back = cloth.desc
        assert abs(back.self_collision_thickness - 0.005) < 1e-9
        assert back.self_collision_relative == 0.0
    desc.self_collision_relative = -1.0
    with pytest.raises(fraccloth.Error) as e:
        fraccloth.Cloth.grid(desc)
    assert "self_collision_relative" in str(e.value)


def test_triangle_mesh_collider_and_self_collision():
    """A towel falls onto a box mesh moved each step: no vertex ends inside the box; bad
    meshes raise with the library's status."""
    desc = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    desc.width, desc.height, desc.spacing = 21, 21, 0.02
    desc.self_collision_thickness = 0.005
    box = np.array([[x, y, z] for y in (-0.05, 0.05) for (x, z) in ((-0.1, -0.1), (0.1, -0.1), (0.1, 0.1), (-0.1, 0.1))])
    faces = [[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4],
             [2, 3, 7], [2, 7, 6], [1, 2, 6], [1, 6, 5], [3, 0, 4], [3, 4, 7]]
    with fraccloth.Cloth.grid(desc) as cloth:
        p = cloth.positions
        flat = np.stack([p[:, 0] - 0.2, np.full(len(p), 0.07), p[:, 1] + 0.2], axis=1)
        cloth.positions = flat
        mesh = cloth.add_mesh_collider(box, faces)
        assert cloth.mesh_collider_size(mesh) == (8, 12)
        for f in range(30):
            cloth.set_mesh_collider(mesh, box + [0.0, 0.001 * f, 0.0])
            cloth.step(1.0 / 30.0)
        x = cloth.positions
        top = 0.05 + 0.029
        inside = (np.abs(x[:, 0]) < 0.1) & (np.abs(x[:, 2]) < 0.1) & (np.abs(x[:, 1] - 0.029) < 0.05)
        assert not inside.any()
        assert x[:, 1].max() < top + 0.03 and x[:, 1].min() < top - 0.05
        stats = cloth.collision_stats()
        assert isinstance(stats, fraccloth.CollisionStats)
        assert stats.unresolved == 0 and stats.passages >= stats.zone_steps
        with pytest.raises(fraccloth.Error) as e:
            cloth.add_mesh_collider(box, [[0, 1, 99]])
        assert e.value.status == 3
        with pytest.raises(fraccloth.Error):
            cloth.set_mesh_collider(mesh, box[:7])


def test_a_fixed_substep_too_long_for_self_collision_is_split_and_counted():
    """A cloth flung at 0.5 m/s with self-collision 6 mm, one 1/30 s substep a call: the substep
    is taken in pieces (at least the 8 its speed predicts), and both statistics say so; a cloth
    without self-collision splits nothing."""
    desc = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    desc.width, desc.height, desc.spacing = 31, 21, 0.02
    desc.max_substep = 0.0
    plain = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    plain.width, plain.height, plain.spacing, plain.max_substep = 31, 21, 0.02, 0.0
    desc.self_collision_thickness = 0.006
    for d, split in ((desc, True), (plain, False)):
        with fraccloth.Cloth.grid(d) as cloth:
            assert cloth.step_limit_stats() == fraccloth.StepLimitStats(0, 0, 0)
            v = np.zeros((cloth.vertex_count, 3))
            v[:, 2] = 0.5
            cloth.velocities = v
            cloth.step(1.0 / 30.0)
            pieces = cloth.step_stats().substeps
            stats = cloth.step_limit_stats()
            if split:
                assert 8 <= pieces <= 32
                assert stats.split_substeps == 1 and stats.pieces == pieces
            else:
                assert pieces == 1 and stats == fraccloth.StepLimitStats(0, 0, 0)


def test_a_description_prints_its_fields():
    desc = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    text = repr(desc)
    assert text.startswith("FcClothDesc(") and "added_mass=8.0" in text and "form_drag_scale=0.01" in text and "skin_drag_unsteady=1.36" in text and "gravity=(0.0, -9.81, 0.0)" in text
    assert str(desc) == text and text.count("=") == len(fraccloth.FcClothDesc._fields_)


def test_a_wrong_argument_type_is_a_type_error_that_names_the_call():
    """ctypes' own conversion error does not escape: a caller sees a TypeError naming the call."""
    cloth = fraccloth.Cloth.grid()
    for bad in (lambda: cloth.step("a frame"), lambda: cloth.step_substeps(1 / 30, "four")):
        with pytest.raises(TypeError, match="fraccloth: fc_cloth_step") as info:
            bad()
        assert not isinstance(info.value, ctypes.ArgumentError)
    cloth.step(1e-4)  # still usable


def test_a_colliders_own_margin():
    desc = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    desc.width, desc.height = 5, 5
    cloth = fraccloth.Cloth.grid(desc)
    cid = cloth.add_sphere((0.0, -1.0, 0.0), 0.1)
    assert cloth.collider_margin(cid) == pytest.approx(desc.collision_margin)
    cloth.set_collider_margin(cid, 0.03)
    assert cloth.collider_margin(cid) == pytest.approx(0.03)
    with pytest.raises(fraccloth.Error):
        cloth.set_collider_margin(cid, -1.0)
    with pytest.raises(fraccloth.Error):
        cloth.collider_margin(99)
