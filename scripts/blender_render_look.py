"""Bakes the underwater towel with the Blender add-on and renders the look with Cycles (CPU),
headless, into docs/blender-underwater-strip.png: four moments of one swing, side by side.

A 0.6 m x 0.4 m towel (61 x 41 vertices) hangs in a tank from its top edge; the whole object is
swung 4 cm at 0.5 Hz across its face (keyframed every frame, so the add-on's pins follow the
animation); the *Underwater towel* preset, automatic time step; 10 s at 30 fps.

Run with a Python that has `bpy` and the `fraccloth` package (`bash .ci/bindings` makes one):
    target/bindings-venv/bin/python scripts/blender_render_look.py [OUT.png]
"""

import math
import sys
import time
from pathlib import Path

import bpy
import addon_utils
import numpy as np

REPO = Path(__file__).resolve().parents[1]
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else REPO / "docs" / "blender-underwater-strip.png"
FPS, SECONDS = 30, 10
MOMENTS = [8.0, 8.5, 9.0, 9.5]  # one drive period (2 s) sampled every quarter, after the start-up
W, H = 300, 420

sys.path.insert(0, str(REPO / "bindings" / "blender"))
bpy.ops.wm.read_factory_settings(use_empty=True)
assert addon_utils.enable("fraccloth_blender", default_set=True, handle_error=None) is not None
scene = bpy.context.scene
scene.render.fps = FPS
scene.frame_start, scene.frame_end = 1, 1 + FPS * SECONDS

# The towel: a 61 x 41 grid, vertical in the x-z plane, top edge at z = 0.
bpy.ops.mesh.primitive_grid_add(x_subdivisions=60, y_subdivisions=40, size=1.0)
towel = bpy.context.active_object
towel.name = "Towel"
for v in towel.data.vertices:
    x, y = v.co.x * 0.6, v.co.y * 0.4
    v.co = (x, 0.0, y - 0.2)
pins = towel.vertex_groups.new(name="pins")
pins.add([v.index for v in towel.data.vertices if v.co.z > -1e-6], 1.0, "REPLACE")
# The swing: 4 cm across the face (y) at 0.5 Hz, a keyframe per frame.
for f in range(scene.frame_start, scene.frame_end + 1):
    t = (f - scene.frame_start) / FPS
    towel.location = (0.0, 0.04 * math.sin(2 * math.pi * 0.5 * t), 0.0)
    towel.keyframe_insert("location", index=1, frame=f)
s = towel.fraccloth
s.preset = "UNDERWATER"
s.cache_path = str(OUT.parent / "blender-towel")
t0 = time.time()
assert bpy.ops.fraccloth.bake() == {"FINISHED"}
print(f"baked {SECONDS} s in {time.time() - t0:.1f} s")

# Looks: a cloth material, a tank (floor and back wall), blue-green water light, a camera.
mat = bpy.data.materials.new("Cloth")
mat.use_nodes = True
bsdf = mat.node_tree.nodes["Principled BSDF"]
bsdf.inputs["Base Color"].default_value = (0.6, 0.18, 0.12, 1.0)
bsdf.inputs["Roughness"].default_value = 0.8
towel.data.materials.append(mat)
towel.data.polygons.foreach_set("use_smooth", [True] * len(towel.data.polygons))
tank = bpy.data.materials.new("Tank")
tank.use_nodes = True
tank.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (0.12, 0.3, 0.35, 1.0)
bpy.ops.mesh.primitive_plane_add(size=3.0, location=(0.0, 0.0, -0.6))
bpy.context.active_object.data.materials.append(tank)
bpy.ops.mesh.primitive_plane_add(size=3.0, location=(0.0, 0.8, 0.0), rotation=(math.pi / 2, 0.0, 0.0))
bpy.context.active_object.data.materials.append(tank)
world = bpy.data.worlds.new("Water")
world.use_nodes = True
world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.05, 0.18, 0.22, 1.0)
world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.3
scene.world = world
# A key light from above and to the side, grazing the cloth so its bumps shade; a weak fill.
bpy.ops.object.light_add(type="SUN", location=(0.0, 0.0, 1.0), rotation=(math.radians(70), 0.0, math.radians(-60)))
bpy.context.active_object.data.energy = 4.0
bpy.ops.object.light_add(type="AREA", location=(0.8, -1.0, 0.0))
fill = bpy.context.active_object
fill.data.energy = 15.0
fill.data.size = 1.0
fill.rotation_euler = (math.radians(90), 0.0, math.radians(40))
# Three-quarter view from the side, so the bumps show in the outline too.
bpy.ops.object.camera_add(location=(1.0, -0.45, -0.12), rotation=(math.radians(88), 0.0, math.radians(66)))
scene.camera = bpy.context.active_object
scene.camera.data.lens = 40
scene.render.engine = "CYCLES"
scene.cycles.device = "CPU"
scene.cycles.samples = 24
scene.render.resolution_x, scene.render.resolution_y = W, H
scene.render.film_transparent = False

strip = np.zeros((H, W * len(MOMENTS), 4), dtype=np.float32)
for k, t in enumerate(MOMENTS):
    scene.frame_set(scene.frame_start + round(t * FPS))
    scene.render.filepath = str(OUT.parent / f"_frame{k}.png")
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(scene.render.filepath)
    px = np.empty(W * H * 4, dtype=np.float32)
    img.pixels.foreach_get(px)
    strip[:, k * W:(k + 1) * W] = px.reshape(H, W, 4)
    bpy.data.images.remove(img)
    Path(scene.render.filepath).unlink()
out = bpy.data.images.new("strip", W * len(MOMENTS), H)
out.pixels.foreach_set(strip.ravel())
out.filepath_raw = str(OUT)
out.file_format = "PNG"
out.save()
for ext in (".pc2", ".mdd"):
    Path(str(OUT.parent / "blender-towel") + ext).unlink(missing_ok=True)
print(f"wrote {OUT}")
