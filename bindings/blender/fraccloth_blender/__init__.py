"""fraccloth for Blender: simulate the active mesh as cloth underwater.

Physics > fraccloth panel (Properties editor, Physics tab). "Bake underwater cloth":
- the active mesh object is the cloth (triangles and quads; apply its scale first);
- vertices of the vertex group named in "Pin group" are pinned with their group weight
  (1 = held in place, less = a soft pin);
- every other selected mesh object is a collider (cameras, lights and empties are not). "Collider shape" Mesh (the default) uses each mesh
  object as it is: its evaluated mesh every frame (armatures, shape keys, modifiers), closed
  meshes with an inside the cloth is pushed out of. Fitted (faster) fits a shape instead: a flat
  object (one dimension near zero) is an infinite plane through its origin along its local Z
  axis, a long one (longest dimension over twice the next) a capsule along that axis, any other
  a sphere of half its largest dimension around its origin (objects that are not meshes are
  always fitted). "Collider friction" and "Collision margin" apply to them all, except a
  collider whose own panel says "As a collider: Own friction" or "Own margin" (its own then);
- "Self-collision" (a thickness in m, 0 = off) keeps the cloth from passing through itself;
- the scene's frame range is baked at the scene's frame rate, each frame split into steps of
  "Time step"; the result is written to a PC2 (or MDD) point cache by the fraccloth library and
  attached with a Mesh Cache modifier.

Settings are per object (each cloth its own preset, values and cache file). The cloth is
simulated in world space, following its animated pins and colliders frame by frame, and the
cache holds each frame in the object's own frame, as the Mesh Cache modifier expects.

Needs the `fraccloth` Python package (bindings/python) importable from Blender's Python:
`pip install ./bindings/python` into it, or put the package (with its _lib folder) next to
this add-on.
"""

bl_info = {
    "name": "fraccloth: underwater cloth",
    "author": "fraccloth developers",
    "version": (0, 9, 34),
    "blender": (4, 2, 0),
    "location": "Properties > Physics > fraccloth",
    "description": "Cloth that moves as if underwater (fractional mass-spring model), baked to a point cache",
    "category": "Physics",
    "license": "MIT OR Apache-2.0",
}

import math
import os
import sys

import bpy
import numpy as np
from mathutils import Vector

_here = os.path.dirname(os.path.abspath(__file__))
if _here not in sys.path:
    sys.path.append(_here)  # a vendored `fraccloth` package next to the add-on

HISTORY_ITEMS = [
    ("SOE", "Accurate memory", "The fractional terms' whole memory at constant cost (sum of exponentials)"),
    ("PAPER", "Paper (u = 3)", "The paper's truncated history, to reproduce its pictures"),
    ("OFF", "Off", "No memory: the underwater towel's (its look comes from the water's inertia and drag)"),
]
INTEGRATOR_ITEMS = [
    ("SYMPLECTIC", "Symplectic Euler", "Fast; small time steps (about 1 ms)"),
    ("EXPLICIT", "Explicit Euler", "The paper's integrator; small time steps"),
    ("IMPLICIT", "Implicit Euler", "Stable at large steps (a frame); first order, so it damps fast motion: with the automatic step it takes substeps short enough for the motion (a 1-2 Hz swing: up to 1.4 times as many as symplectic Euler, each several times dearer); at a fixed step of a frame a 1-2 Hz swing's free edge moves 15-70 % less than with symplectic Euler. For slow scenes"),
    ("SYMPLECTIC2", "Symplectic, 2nd order", "Extrapolated symplectic Euler: error shrinks with the square of the step; 3x the work per step"),
    ("IMPLICIT2", "Implicit, 2nd order", "Extrapolated implicit Euler: second order and stable at a frame; 3x the work per step"),
    ("XPBD", "XPBD (fewer substeps)", "Stretch and shear springs as compliant constraints: with the automatic step a 60 fps frame takes about 3 substeps instead of 14; the springs act softer: fewer small ripples in a brisk swing, and a tall cloth hangs longer (keep Symplectic Euler for it)"),
]
FORMAT_ITEMS = [("PC2", "PC2", "PC2 point cache"), ("MDD", "MDD", "MDD point cache")]
COLLIDER_ITEMS = [
    ("MESH", "Mesh", "Each collider object's own mesh, as evaluated every frame (armatures, shape keys, modifiers)"),
    ("FITTED", "Fitted (faster)", "A sphere, capsule or plane fitted to each collider object"),
]


DAMPING_ITEMS = [
    ("FRACTIONAL", "Fractional (paper)", "Springs resist the half-derivative of their ends' motion: the paper's Eq. 5"),
    ("STRAIN", "Fractional, turn-proof", "Half-derivative of each spring's stretch: like the paper's, without its grid-scale zigzag"),
    ("VELOCITY", "Ordinary", "Springs resist how fast they stretch (classic damped springs)"),
    ("NONE", "None", "Springs do not damp"),
]

# Presets in an artist's words: (label, tooltip, values). "Underwater towel" is the library's
# FC_PRESET_UNDERWATER, read from the library when chosen (docs/underwater.md); the others
# differ visibly from it.
PRESETS = {
    "UNDERWATER": ("Underwater towel", "A wet towel in water: slow bumps that travel down it (the library's underwater preset)", None),
    "SILK": ("Light silk", "A thin, light scarf: billows and drifts, settles slowly", {
        "stretch_stiffness": 4.0, "shear_stiffness": 0.8, "bend_stiffness": 0.02, "bend_spacing": 0.01,
        "damping_mode": "VELOCITY", "spring_damping": 0.005, "history_drag": 0.0, "viscous_drag": 0.0,
        "normal_drag": 0.0, "mass_per_area": 0.1, "cloth_density": 1300.0, "water_density": 1000.0,
        "entrained_mass": 2.0, "added_mass": 0.0, "form_drag": 1.0, "form_drag_scale": 0.0, "skin_drag": 0.5, "skin_drag_unsteady": 0.0, "skin_drag_memory": 1.0, "coarse_added_mass": 0.0,
        "history": "OFF", "integrator": "SYMPLECTIC"}),
    "CANVAS": ("Heavy canvas", "A heavy sheet: sinks and folds in broad, slow waves", {
        "stretch_stiffness": 40.0, "shear_stiffness": 8.0, "bend_stiffness": 4.0, "bend_spacing": 0.01,
        "damping_mode": "VELOCITY", "spring_damping": 0.05, "history_drag": 0.0, "viscous_drag": 0.0,
        "normal_drag": 0.0, "mass_per_area": 2.0, "cloth_density": 1500.0, "water_density": 1000.0,
        "entrained_mass": 10.0, "added_mass": 0.0, "form_drag": 1.5, "form_drag_scale": 0.0, "skin_drag": 0.0, "skin_drag_unsteady": 0.0, "skin_drag_memory": 1.0, "coarse_added_mass": 0.0,
        "history": "OFF", "integrator": "SYMPLECTIC"}),
    "PAPER": ("Fractional (paper)", "The paper's fractional cloth: half-derivative springs and drags, no water inertia", {
        "stretch_stiffness": 10.0, "shear_stiffness": 2.0, "bend_stiffness": 0.5, "bend_spacing": 0.0,
        "damping_mode": "FRACTIONAL", "spring_damping": 0.35, "history_drag": 2e-3, "viscous_drag": 1e-3,
        "normal_drag": 0.0, "mass_per_area": 1.0, "cloth_density": 1100.0, "water_density": 1000.0,
        "entrained_mass": 0.0, "added_mass": 0.0, "form_drag": 0.0, "form_drag_scale": 0.0, "skin_drag": 0.0, "skin_drag_unsteady": 0.0, "skin_drag_memory": 1.0, "coarse_added_mass": 0.0,
        "history": "SOE", "integrator": "SYMPLECTIC"}),
}
PRESET_ITEMS = [("CUSTOM", "Custom", "Your own values")] + [(k, v[0], v[1]) for k, v in PRESETS.items()]
# A new object starts on "Underwater towel": the values' defaults below are the library's
# FC_PRESET_UNDERWATER (a test compares them with the library's own).


def _library_preset():
    """The panel's values of the library's FC_PRESET_UNDERWATER (the panel's drags are per
    1 cm^2 of cloth, the library's per m^2)."""
    import fraccloth

    d = fraccloth.preset_desc(fraccloth.PRESET_UNDERWATER)
    modes = {
        fraccloth.SPRING_DAMPING_FRACTIONAL: "FRACTIONAL",
        fraccloth.SPRING_DAMPING_FRACTIONAL_STRAIN: "STRAIN",
        fraccloth.SPRING_DAMPING_VELOCITY: "VELOCITY",
        fraccloth.SPRING_DAMPING_NONE: "NONE",
    }
    integrators = {
        fraccloth.INTEGRATOR_SYMPLECTIC_EULER: "SYMPLECTIC",
        fraccloth.INTEGRATOR_EXPLICIT_EULER: "EXPLICIT",
        fraccloth.INTEGRATOR_IMPLICIT_EULER: "IMPLICIT",
        fraccloth.INTEGRATOR_EXTRAPOLATED_SYMPLECTIC: "SYMPLECTIC2",
        fraccloth.INTEGRATOR_EXTRAPOLATED_IMPLICIT: "IMPLICIT2",
        fraccloth.INTEGRATOR_XPBD: "XPBD",
    }
    fractional = d.history_drag or d.history_drag_per_area or d.spring_damping_mode in (
        fraccloth.SPRING_DAMPING_FRACTIONAL, fraccloth.SPRING_DAMPING_FRACTIONAL_STRAIN)
    return {
        "stretch_stiffness": d.stretch_stiffness, "shear_stiffness": d.shear_stiffness,
        "bend_stiffness": d.bend_stiffness, "bend_spacing": d.bend_reference_spacing,
        "damping_mode": modes[d.spring_damping_mode],
        "spring_damping": d.spring_damping,
        # The library's per-particle drags are 0 in this preset; per area, to the panel's 1 cm^2.
        "history_drag": d.history_drag_per_area * 1e-4, "viscous_drag": d.viscous_drag_per_area * 1e-4,
        "normal_drag": d.normal_drag_per_area * 1e-4,
        "mass_per_area": d.areal_density, "cloth_density": d.cloth_density, "water_density": d.water_density,
        "entrained_mass": d.entrained_mass, "added_mass": d.added_mass, "form_drag": d.form_drag,
        "form_drag_scale": d.form_drag_scale, "skin_drag": d.skin_drag,
        "skin_drag_unsteady": d.skin_drag_unsteady, "skin_drag_memory": d.skin_drag_memory or SKIN_MEMORY,
        # The patch size is unused while the large-scale water is off (the preset's 0): the
        # panel then shows a usable one.
        "coarse_added_mass": d.coarse_added_mass, "coarse_length": d.coarse_length or COARSE_LENGTH,
        "history": "SOE" if fractional else "OFF",
        "integrator": integrators[d.integrator],
    }


# The panel's patch size for the large-scale water when the library's preset gives none (its
# term off), m: a few patches across a towel (docs/underwater.md, "The water's inertia by scale").
COARSE_LENGTH = 0.2
# The skin drag's memory the panel shows while its unsteady part is off (the library's 0 then).
SKIN_MEMORY = 1.0


# True while a preset writes its values (so that they do not count as the artist's edits).
_APPLYING = [False]


def _apply_preset(self, context):
    values = PRESETS.get(self.preset)
    if values is None:
        return
    _APPLYING[0] = True
    try:
        for name, value in (values[2] or _library_preset()).items():
            setattr(self, name, value)
    finally:
        _APPLYING[0] = False


def _edited(self, context):
    """An artist's edit of a value a preset sets: the label says Custom from then on."""
    if not _APPLYING[0] and self.preset != "CUSTOM":
        _APPLYING[0] = True
        try:
            self.preset = "CUSTOM"
        finally:
            _APPLYING[0] = False


class FracclothSettings(bpy.types.PropertyGroup):
    preset: bpy.props.EnumProperty(name="Preset", items=PRESET_ITEMS, default="UNDERWATER", update=_apply_preset,
                                   description="Set every value below from a preset (then change what you like)")
    pin_group: bpy.props.StringProperty(name="Pin group", description="Vertex group of pinned vertices (weight = how firmly)", default="pins")
    stretch_stiffness: bpy.props.FloatProperty(name="Stretch", description="How hard the cloth resists stretching (spring constant, N/m)", default=10.0, min=0.0, soft_max=200.0, update=_edited)
    shear_stiffness: bpy.props.FloatProperty(name="Shear", description="How hard it resists shearing (N/m)", default=2.0, min=0.0, soft_max=50.0, update=_edited)
    bend_stiffness: bpy.props.FloatProperty(name="Bend", description="How hard it resists bending (N/m); low values give fine folds", default=0.5, min=0.0, soft_max=20.0, update=_edited)
    bend_spacing: bpy.props.FloatProperty(name="Bend measured at", description="The mesh spacing the Bend value holds at, m: a finer or coarser mesh gets its bend springs scaled so it bends alike (0: the same spring constant at any spacing, as in the paper)", default=0.01, min=0.0, soft_max=0.1, precision=3, update=_edited)
    damping_mode: bpy.props.EnumProperty(name="Spring damping", items=DAMPING_ITEMS, default="VELOCITY", update=_edited)
    spring_damping: bpy.props.FloatProperty(name="Damping", description="How much the springs damp their own motion (N s^1/2/m fractional, N s/m ordinary)", default=0.003, min=0.0, soft_max=1.0, precision=4, update=_edited)
    history_drag: bpy.props.FloatProperty(name="History drag", description="Water's memory drag per 1 cm^2 of cloth (N s^1/2/m)", default=0.0, min=0.0, soft_max=0.05, precision=5, update=_edited)
    viscous_drag: bpy.props.FloatProperty(name="Viscous drag", description="Drag in proportion to speed, per 1 cm^2 of cloth (N s/m)", default=0.0, min=0.0, soft_max=0.05, precision=5, update=_edited)
    normal_drag: bpy.props.FloatProperty(name="Normal drag", description="Drag on motion across the cloth, per 1 cm^2 (N s/m)", default=0.0, min=0.0, soft_max=0.05, precision=5, update=_edited)
    mass_per_area: bpy.props.FloatProperty(name="Weight", description="Mass of the wet cloth per square metre (kg/m^2)", default=1.0, min=1e-6, soft_max=5.0, update=_edited)
    cloth_density: bpy.props.FloatProperty(name="Cloth density", description="Density of the wet cloth (kg/m^3): above the water's it sinks, below it floats", default=1100.0, min=1.0, soft_min=500.0, soft_max=3000.0, update=_edited)
    water_density: bpy.props.FloatProperty(name="Water density", description="kg/m^3 (1000 fresh water, 1025 sea water, 0 for air)", default=1000.0, min=0.0, soft_max=1100.0, update=_edited)
    entrained_mass: bpy.props.FloatProperty(name="Water carried", description="Water the cloth drags along as it moves, kg per m^2 of cloth: makes it slow and heavy in the water", default=0.0, min=0.0, soft_max=40.0, update=_edited)
    added_mass: bpy.props.FloatProperty(name="Added mass (across)", description="Water moved by motion across the cloth only, kg per m^2", default=8.0, min=0.0, soft_max=40.0, update=_edited)
    form_drag: bpy.props.FloatProperty(name="Form drag", description="Drag coefficient of the cloth moving face first through water (1 to 2 for a sheet)", default=1.0, min=0.0, soft_max=4.0, update=_edited)
    form_drag_scale: bpy.props.FloatProperty(name="Drag ripple size", description="Ripples shorter than about this shed little drag, so a brisk swing keeps its small bumps while the cloth's motion at large is slowed in full (0: every ripple is dragged), m", default=0.010, min=0.0, soft_max=0.1, precision=3, update=_edited)
    skin_drag: bpy.props.FloatProperty(name="Skin drag", description="Drag of water sliding along the cloth in a steady flow, N s/m^3", default=1.15, min=0.0, soft_max=5.0, update=_edited)
    skin_drag_unsteady: bpy.props.FloatProperty(name="Skin drag, to and fro", description="More drag on sliding that changes faster than the memory below (a swing's motion along the cloth), N s/m^3; 0: off", default=1.36, min=0.0, soft_max=5.0, update=_edited)
    skin_drag_memory: bpy.props.FloatProperty(name="Skin drag memory", description="How long a flow along the cloth takes to count as steady, s", default=1.0, min=1e-3, soft_max=10.0, update=_edited)
    coarse_added_mass: bpy.props.FloatProperty(name="Added mass at large", description="More water carried when the cloth moves as a whole (smoother than the patch size), kg per m^2; ripples carry only the added mass across. 0: off (the presets). Costs a small solve a step", default=0.0, min=0.0, soft_max=200.0, update=_edited)
    coarse_length: bpy.props.FloatProperty(name="Patch size", description="Size of the patches over which the cloth's motion counts as motion at large, m (the library refuses one that makes more than 256 patches over the cloth, naming one that fits)", default=COARSE_LENGTH, min=1e-3, soft_max=1.0, precision=3, update=_edited)
    current: bpy.props.FloatVectorProperty(name="Current", description="Water current, m/s (world)", default=(0.0, 0.0, 0.0), size=3)
    history: bpy.props.EnumProperty(name="History", items=HISTORY_ITEMS, default="OFF", update=_edited)
    integrator: bpy.props.EnumProperty(name="Integrator", items=INTEGRATOR_ITEMS, default="SYMPLECTIC", update=_edited)
    auto_step: bpy.props.BoolProperty(name="Automatic time step", description="The library splits each frame into as few steps as the cloth needs (from its springs, weight, water, colliders and pins) and retries a frame that fails with more", default=True)
    time_step: bpy.props.FloatProperty(name="Time step", description="Longest step when not automatic, s", default=5e-4, min=1e-6, max=0.1, precision=5)
    friction: bpy.props.FloatProperty(name="Collider friction", description="How much the colliders grip the cloth (0 = slippery, 1 = grippy); a collider with its own friction (its panel's \"As a collider\") uses that", default=0.0, min=0.0, soft_max=1.0)
    collider_own_friction: bpy.props.BoolProperty(name="Own friction", description="When this object is a collider of a fraccloth cloth, it grips the cloth with its own friction below instead of the cloth's Collider friction", default=False)
    collider_friction: bpy.props.FloatProperty(name="Friction", description="How much this object grips a fraccloth cloth that collides with it (0 = slippery, 1 = grippy)", default=0.5, min=0.0, soft_max=1.0)
    collider_own_margin: bpy.props.BoolProperty(name="Own margin", description="When this object is a collider of a fraccloth cloth, it keeps the cloth at its own distance below instead of the cloth's Collision margin", default=False)
    collider_margin: bpy.props.FloatProperty(name="Margin", description="Distance from this object at which a fraccloth cloth is pushed away, m", default=0.01, min=0.0, soft_max=0.05, precision=4)
    collision_margin: bpy.props.FloatProperty(name="Collision margin", description="Distance from a collider at which the cloth is pushed away, m", default=0.01, min=0.0, soft_max=0.05)
    collider_shape: bpy.props.EnumProperty(name="Collider shape", items=COLLIDER_ITEMS, default="MESH",
                                           description="How collider objects are seen: their own mesh every frame, or a fitted sphere, capsule or plane (faster)")
    self_collision: bpy.props.FloatProperty(name="Self-collision", description="Distance the cloth keeps from itself, m (0 = off); a few mm for a cloth of 1-2 cm spacing", default=0.0, min=0.0, soft_max=0.02, precision=4)
    self_collision_spacings: bpy.props.FloatProperty(name="Self-collision (spacings)", description="Distance the cloth keeps from itself in the mesh's spacings, added to Self-collision (0 = none): one value for any resolution, 0.3-0.5 keeps a fold apart without touching neighbours", default=0.0, min=0.0, soft_max=1.0, precision=2)
    self_friction: bpy.props.FloatProperty(name="Self friction", description="How much the cloth grips itself where it touches (0 = slippery)", default=0.0, min=0.0, soft_max=1.0)
    use_scene_range: bpy.props.BoolProperty(name="Scene frame range", default=True,
                                            description="Bake the scene's frame range; off: the range below")
    frame_start: bpy.props.IntProperty(name="Start", description="First frame of the bake (the cloth's rest state)", default=1, min=0)
    frame_end: bpy.props.IntProperty(name="End", description="Last frame of the bake", default=250, min=0)
    cache_format: bpy.props.EnumProperty(name="Format", items=FORMAT_ITEMS, default="PC2")
    cache_path: bpy.props.StringProperty(name="Cache file", subtype="FILE_PATH", default="",
                                         description="Where the cache goes; empty: a 'fraccloth' folder next to the .blend, named after the object")


def _evaluated(obj, triangles=False):
    """World positions (N, 3) of `obj`'s mesh as Blender evaluates it at the current frame
    (object transform, parents, armatures, shape keys, hooks, modifiers), and its triangles
    (M, 3) when asked."""
    deps = bpy.context.evaluated_depsgraph_get()
    ev = obj.evaluated_get(deps)
    me = ev.to_mesh()
    tris = None
    try:
        co = np.empty(3 * len(me.vertices), dtype=np.float64)
        me.vertices.foreach_get("co", co)
        if triangles:
            me.calc_loop_triangles()
            tris = np.empty(3 * len(me.loop_triangles), dtype=np.uint32)
            me.loop_triangles.foreach_get("vertices", tris)
            tris = tris.reshape(-1, 3)
    finally:
        ev.to_mesh_clear()
    m = np.array(ev.matrix_world, dtype=np.float64)
    return co.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3], tris


def frame_range(scene, s):
    """(first, last) frame of a bake with settings `s`: the scene's range, or the settings' own."""
    if s.use_scene_range:
        return scene.frame_start, scene.frame_end
    if s.frame_end < s.frame_start:
        raise ValueError(f"the bake's frame range ends ({s.frame_end}) before it starts ({s.frame_start})")
    return s.frame_start, s.frame_end


def unit_scale(scene):
    """Metres per Blender unit (Scene > Units > Unit Scale): the library works in metres."""
    return float(scene.unit_settings.scale_length)


def _in_metres(spec, u):
    """A collider spec (`collider_specs_for`) in metres: lengths times `u` metres per unit."""
    kind = spec[0]
    if kind == "mesh":
        return (kind, spec[1] * u, spec[2])
    if kind == "plane":
        return (kind, tuple(u * c for c in spec[1]), spec[2])
    if kind == "capsule":
        return (kind, tuple(u * c for c in spec[1]), tuple(u * c for c in spec[2]), u * spec[3])
    return (kind, tuple(u * c for c in spec[1]), u * spec[2])


def colliders_of(context, obj):
    """The objects `obj` collides with: mesh objects with Blender's own Collision physics on
    (the setting Blender's cloth reads), and mesh objects selected beside it."""
    chosen = []
    for o in context.scene.objects:
        if o is obj or o.type != "MESH":
            continue
        physics = any(m.type == "COLLISION" for m in o.modifiers)
        if physics or o.select_get():
            chosen.append(o)
    return chosen


def _mesh_spec(o):
    """("mesh", world positions (N, 3), triangles (M, 3)) of a mesh object as Blender evaluates
    it at the current frame (armature, shape keys, modifiers, parents)."""
    co, tris = _evaluated(o, triangles=True)
    return ("mesh", co, tris)


def collider_objects(s, others):
    """The objects of `others` that become colliders under the settings `s`, in the order of
    `collider_specs_for`'s specs: meshes (with faces, for "Collider shape" Mesh)."""
    if s.collider_shape != "MESH":
        return [o for o in others if o.type == "MESH"]
    return [o for o in others if o.type == "MESH" and len(o.data.polygons) > 0]


def collider_friction_of(s, o):
    """The friction collider `o` grips the cloth of settings `s` with: its own ("As a collider:
    Own friction") or the cloth's "Collider friction"."""
    own = getattr(o, "fraccloth", None)
    if own is not None and own.collider_own_friction:
        return own.collider_friction
    return s.friction


def collider_margin_of(o):
    """Collider `o`'s own margin in metres of the library (its "As a collider: Own margin"),
    or None for the cloth's Collision margin."""
    own = getattr(o, "fraccloth", None)
    if own is not None and own.collider_own_margin:
        return own.collider_margin
    return None


def collider_specs_for(s, others):
    """The colliders at the current frame as the settings `s` see them: each mesh object as its
    evaluated mesh ("Collider shape" Mesh), or fitted shapes (`_world_specs`), one per object of
    `collider_objects`."""
    if s.collider_shape != "MESH":
        return _world_specs(others)
    return [_mesh_spec(o) for o in collider_objects(s, others)]


def _world_specs(others):
    """(kind, args) for every collider object, in world coordinates, at the current frame, fitted
    to its dimensions (its bounding box in its own axes): a flat object (one dimension below 1e-6
    of the largest) is a plane through its origin along its local z axis; a long one (its largest
    dimension more than twice the next) a capsule along that axis through its origin, as long as
    the object, its radius half the next dimension; anything else a sphere around its origin whose
    radius is half its largest dimension."""
    specs = []
    for o in others:
        if o.type != "MESH":
            continue  # a camera, a light, an empty: selected, but not a collider
        dims = o.dimensions
        center = o.matrix_world.translation.copy()
        order = sorted(range(3), key=lambda k: dims[k])
        if dims[order[0]] < 1e-6 * max(max(dims), 1e-9):
            normal = (o.matrix_world.to_3x3() @ Vector((0.0, 0.0, 1.0))).normalized()
            specs.append(("plane", tuple(center), tuple(normal)))
        elif dims[order[2]] > 2.0 * dims[order[1]]:
            axis = Vector((0.0, 0.0, 0.0))
            axis[order[2]] = 1.0
            radius = 0.5 * dims[order[1]]
            direction = (o.matrix_world.to_3x3() @ axis).normalized()
            half = 0.5 * dims[order[2]] - radius
            specs.append(("capsule", tuple(center - half * direction), tuple(center + half * direction), radius))
        else:
            specs.append(("sphere", tuple(center), 0.5 * max(dims)))
    return specs


def collider_specs(obj, others):
    """The colliders at the current frame (world coordinates; `obj` is unused and kept for
    callers of earlier versions)."""
    return _world_specs(others)


def world_positions(obj):
    """The evaluated mesh's vertex positions in world coordinates at the current frame (object
    transform, parents, armatures, shape keys, hooks: whatever Blender evaluates), (N, 3)."""
    return _evaluated(obj)[0]


def to_local(obj, world):
    """World positions into `obj`'s local frame at the current frame (what the Mesh Cache
    modifier stores)."""
    inv = np.array(obj.matrix_world.inverted(), dtype=np.float64)
    return world @ inv[:3, :3].T + inv[:3, 3]


def mesh_arrays(obj):
    """Local vertex positions (N, 3) and faces: quads (M, 4) if every face is a quad, else
    triangles (M, 3)."""
    me = obj.data
    pos = np.empty(3 * len(me.vertices), dtype=np.float32)
    me.vertices.foreach_get("co", pos)
    if all(len(p.vertices) == 4 for p in me.polygons):
        faces = np.empty(4 * len(me.polygons), dtype=np.uint32)
        me.polygons.foreach_get("vertices", faces)
        return pos.reshape(-1, 3), faces.reshape(-1, 4)
    me.calc_loop_triangles()
    tris = np.empty(3 * len(me.loop_triangles), dtype=np.uint32)
    me.loop_triangles.foreach_get("vertices", tris)
    return pos.reshape(-1, 3), tris.reshape(-1, 3)


def pin_weights(obj, name):
    group = obj.vertex_groups.get(name)
    w = np.zeros(len(obj.data.vertices), dtype=np.float32)
    if group is None:
        return w
    for v in obj.data.vertices:
        for g in v.groups:
            if g.group == group.index:
                w[v.index] = g.weight
    return np.clip(w, 0.0, 1.0)


def describe(s, scene=None):
    """The library's description (`FcClothDesc`) for the settings `s` in `scene` (its gravity,
    off when the scene's gravity is off, in metres; Earth's without a scene); grid size and time
    step are not in it."""
    import fraccloth

    desc = fraccloth.default_desc()
    desc.total_mass = 0.0
    desc.areal_density = s.mass_per_area
    desc.cloth_density = s.cloth_density
    desc.water_density = s.water_density
    for k in range(3):
        if scene is None:
            desc.gravity[k] = (0.0, 0.0, -9.81)[k]
        else:
            desc.gravity[k] = scene.gravity[k] * unit_scale(scene) if scene.use_gravity else 0.0
        desc.current[k] = s.current[k]
    desc.stretch_stiffness = s.stretch_stiffness
    desc.shear_stiffness = s.shear_stiffness
    desc.bend_stiffness = s.bend_stiffness
    desc.bend_reference_spacing = s.bend_spacing
    desc.spring_damping = s.spring_damping
    desc.spring_damping_mode = {
        "FRACTIONAL": fraccloth.SPRING_DAMPING_FRACTIONAL,
        "STRAIN": fraccloth.SPRING_DAMPING_FRACTIONAL_STRAIN,
        "VELOCITY": fraccloth.SPRING_DAMPING_VELOCITY,
        "NONE": fraccloth.SPRING_DAMPING_NONE,
    }[s.damping_mode]
    # The panel's drags are per 1 cm^2 of cloth; the library takes them per m^2 and multiplies
    # each vertex's own area, so the look does not change with the mesh's resolution.
    desc.history_drag = 0.0
    desc.viscous_drag = 0.0
    desc.normal_drag = 0.0
    desc.history_drag_per_area = s.history_drag / 1e-4
    desc.viscous_drag_per_area = s.viscous_drag / 1e-4
    desc.normal_drag_per_area = s.normal_drag / 1e-4
    desc.entrained_mass = s.entrained_mass
    desc.added_mass = s.added_mass
    desc.form_drag = s.form_drag
    desc.form_drag_scale = s.form_drag_scale
    desc.skin_drag = s.skin_drag
    desc.skin_drag_unsteady = s.skin_drag_unsteady
    desc.skin_drag_memory = s.skin_drag_memory if s.skin_drag_unsteady > 0.0 else 0.0
    desc.coarse_added_mass = s.coarse_added_mass
    desc.coarse_length = s.coarse_length if s.coarse_added_mass > 0.0 else 0.0
    desc.collision_margin = s.collision_margin
    desc.self_collision_thickness = s.self_collision
    desc.self_collision_relative = s.self_collision_spacings
    desc.self_collision_friction = s.self_friction
    fractional = s.damping_mode in ("FRACTIONAL", "STRAIN") and s.spring_damping > 0.0 or s.history_drag > 0.0
    if fractional and s.history == "OFF":
        raise ValueError("fractional damping or a history drag needs a History (Accurate or Paper): with History Off "
                         "they do nothing; choose a History, or Ordinary spring damping and no history drag")
    desc.history_scheme = {"SOE": fraccloth.HISTORY_SOE, "PAPER": fraccloth.HISTORY_TRUNCATED, "OFF": fraccloth.HISTORY_OFF}[s.history]
    desc.history_u = 3
    desc.integrator = {
        "SYMPLECTIC": fraccloth.INTEGRATOR_SYMPLECTIC_EULER,
        "EXPLICIT": fraccloth.INTEGRATOR_EXPLICIT_EULER,
        "IMPLICIT": fraccloth.INTEGRATOR_IMPLICIT_EULER,
        "SYMPLECTIC2": fraccloth.INTEGRATOR_EXTRAPOLATED_SYMPLECTIC,
        "IMPLICIT2": fraccloth.INTEGRATOR_EXTRAPOLATED_IMPLICIT,
        "XPBD": fraccloth.INTEGRATOR_XPBD,
    }[s.integrator]
    return desc


def build_cloth(context, obj, others):
    """The fraccloth cloth for `obj` with its settings, in world coordinates at the current
    frame; returns (cloth, step plan, pinned indices, collider ids)."""
    import fraccloth

    s = obj.fraccloth
    if any(abs(c - 1.0) > 1e-6 for c in obj.matrix_world.to_scale()):
        raise ValueError(f"{obj.name}: apply its scale first (Ctrl+A > Scale)")
    _, faces = mesh_arrays(obj)
    u = unit_scale(context.scene)
    pos = world_positions(obj) * u
    if len(pos) != len(obj.data.vertices):
        raise ValueError(f"{obj.name}: its modifiers change the vertex count; apply or remove them")
    desc = describe(s, context.scene)
    if s.auto_step:
        # The library chooses each frame's substeps from the cloth as it is (and retries a
        # refused frame with more): FC_MAX_SUBSTEP_AUTO.
        desc.max_substep = fraccloth.MAX_SUBSTEP_AUTO
    cloth = fraccloth.Cloth.mesh(desc, pos.astype(np.float32), faces)
    if s.pin_group and obj.vertex_groups.get(s.pin_group) is None:
        names = ", ".join(g.name for g in obj.vertex_groups) or "none"
        raise ValueError(f"{obj.name}: no vertex group named '{s.pin_group}' for the pins (its groups: {names}); "
                         "pick one in Pin group, or clear it for a cloth with no pins")
    w = pin_weights(obj, s.pin_group)
    if w.any():
        cloth.set_pin_weights(w)
    ids = []
    for o, spec in zip(collider_objects(s, others), collider_specs_for(s, others)):
        spec = _in_metres(spec, u)
        if spec[0] == "mesh":
            cid = cloth.add_mesh_collider(spec[1].astype(np.float32), spec[2])
        elif spec[0] == "plane":
            cid = cloth.add_plane(spec[1], spec[2])
        elif spec[0] == "capsule":
            cid = cloth.add_capsule(spec[1], spec[2], spec[3])
        else:
            cid = cloth.add_sphere(spec[1], spec[2])
        cloth.set_collider_friction(cid, collider_friction_of(s, o))
        margin = collider_margin_of(o)
        if margin is not None:
            cloth.set_collider_margin(cid, margin)
        ids.append(cid)
    fps = context.scene.render.fps / context.scene.render.fps_base
    frame_dt = 1.0 / fps
    # None: the library's automatic step splits each frame; else a fixed count of substeps.
    substeps = None if s.auto_step else max(1, math.ceil(frame_dt / s.time_step - 1e-9))
    return cloth, (frame_dt, substeps), np.flatnonzero(w > 0.0).astype(np.uint32), ids


def simulate(context, obj, others):
    """Yields (frame, cloth, local positions) for every frame of the bake's range (`frame_range`),
    in metres inside the library (Blender units times the scene's unit scale). The cloth
    moves in world space; the first frame is the rest state, each next one a frame's worth of
    steps later. Before each frame's steps the pinned vertices' evaluated world positions at that
    frame become the pin targets (approached in a straight line over the substeps; a weight
    below 1 is a soft pin), and every collider is moved to where it is at that frame with the
    velocity that takes it there. Local positions: the cloth in `obj`'s frame at that frame."""
    scene = context.scene
    # An earlier bake's cache must not feed the mesh this one reads.
    ours = [m for m in obj.modifiers if m.type == "MESH_CACHE" and m.name == "fraccloth"]
    shown = [m.show_viewport for m in ours]
    for m in ours:
        m.show_viewport = False
    try:
        yield from _simulate(context, obj, others)
    finally:
        for m, v in zip(ours, shown):
            m.show_viewport = v


def _simulate(context, obj, others):
    scene = context.scene
    s = obj.fraccloth
    first, last = frame_range(scene, s)
    u = unit_scale(scene)
    scene.frame_set(first)
    cloth, (frame_dt, substeps), pinned, ids = build_cloth(context, obj, others)
    specs = lambda: [_in_metres(spec, u) for spec in collider_specs_for(s, others)]  # noqa: E731
    previous = specs()
    for f in range(first, last + 1):
        if f > first:
            scene.frame_set(f)
            if len(pinned):
                cloth.set_pin_targets(pinned, (world_positions(obj)[pinned] * u).astype(np.float32))
            now = specs()
            for cid, old, new in zip(ids, previous, now):
                if new[0] == "mesh":
                    if len(new[1]) != len(old[1]):
                        raise ValueError("a collider's modifiers change its vertex count from frame to frame; apply them or use Collider shape Fitted")
                    # The library moves it there over the frame, with the velocity that takes it there.
                    cloth.set_mesh_collider(cid, new[1].astype(np.float32))
                    continue
                velocity = (np.array(new[1]) - np.array(old[1])) / frame_dt
                if new[0] == "plane":
                    cloth.set_plane(cid, new[1], new[2], velocity)
                elif new[0] == "capsule":
                    cloth.set_capsule(cid, new[1], new[2], new[3], velocity)
                else:
                    cloth.set_sphere(cid, new[1], new[2], velocity)
            previous = now
            if substeps is None:
                cloth.step(frame_dt)
            else:
                cloth.step_substeps(frame_dt, substeps)
        yield f, cloth, to_local(obj, cloth.positions_f64() / u).astype(np.float32)


def cache_path(obj):
    """The object's cache file without extension: its own setting, or a `fraccloth` folder next
    to the .blend (Blender's temporary folder for an unsaved file), named after the object."""
    s = obj.fraccloth
    if s.cache_path:
        return bpy.path.abspath(s.cache_path)
    base = os.path.dirname(bpy.data.filepath) if bpy.data.filepath else bpy.app.tempdir
    return os.path.join(base, "fraccloth", bpy.path.clean_name(obj.name))


class BakeJob:
    """One bake, a frame at a time, so that the interface can show progress and cancel between
    frames. `step()` bakes the next frame and returns True once the cache is complete and
    attached; `cancel()` stops and removes the partial cache, so no cache that looks complete is
    left behind. Raises `fraccloth.Error` or `ValueError` from `step()` (call `cancel()` then)."""

    def __init__(self, context, obj, others):
        import fraccloth

        self.context, self.obj = context, obj
        s = obj.fraccloth
        scene = context.scene
        ext = ".pc2" if s.cache_format == "PC2" else ".mdd"
        path = cache_path(obj)
        self.path = path if path.endswith(ext) else path + ext
        os.makedirs(os.path.dirname(self.path) or ".", exist_ok=True)
        self.format = fraccloth.CACHE_PC2 if s.cache_format == "PC2" else fraccloth.CACHE_MDD
        self.first, last = frame_range(scene, s)
        self.frames = last - self.first + 1
        self.fps = scene.render.fps / scene.render.fps_base
        self.done = 0
        self.cache = None
        self.return_to = scene.frame_current
        # The new bake goes to a file of its own; an earlier bake (its cache modifier, hidden
        # while this one reads the mesh, and its file) stays until this one is complete, so a
        # refused or cancelled re-bake loses nothing.
        self.partial = self.path + ".baking"
        # Check the setup before anything is written: the cloth is built here (and again by the
        # simulation); a bad setup raises now.
        scene.frame_set(self.first)
        try:
            build_cloth(context, obj, others)
        except Exception:
            scene.frame_set(self.return_to)
            raise
        self.frames_left = simulate(context, obj, others)

    def step(self):
        import fraccloth

        scene = self.context.scene
        f, cloth, local = next(self.frames_left)
        if self.cache is None:
            self.cache = fraccloth.Cache(self.partial, self.format, cloth, float(self.first), self.fps, self.frames)
        self.cache.write_positions(local)
        self.done += 1
        if self.done < self.frames:
            return False
        self.frames_left.close()
        self.cache.close()
        self.cache = None
        scene.frame_set(self.return_to)
        # Complete: the new cache replaces the earlier bake.
        for m in list(self.obj.modifiers):
            if m.type == "MESH_CACHE" and m.name == "fraccloth":
                self.obj.modifiers.remove(m)
        os.replace(self.partial, self.path)
        s = self.obj.fraccloth
        mod = self.obj.modifiers.new("fraccloth", "MESH_CACHE")
        mod.cache_format = s.cache_format
        mod.filepath = self.path
        mod.time_mode = "FRAME"
        mod.play_mode = "SCENE"
        mod.frame_start = float(self.first)
        mod.interpolation = "NONE"
        return True

    def cancel(self):
        import fraccloth

        self.frames_left.close()
        if self.cache is not None:
            try:
                self.cache.close()
            except fraccloth.Error:
                pass
            self.cache = None
        if os.path.exists(self.partial):
            os.remove(self.partial)
        self.context.scene.frame_set(self.return_to)


class FRACCLOTH_OT_bake(bpy.types.Operator):
    """Simulate the active mesh underwater and attach the result as a point cache (Esc cancels)"""

    bl_idname = "fraccloth.bake"
    bl_label = "Bake underwater cloth"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "MESH"

    def _start(self, context):
        obj = context.active_object
        return BakeJob(context, obj, colliders_of(context, obj))

    def _fail(self, job, error):
        if job is not None:
            job.cancel()
        self.report({"ERROR"}, f"fraccloth: {error}")
        return {"CANCELLED"}

    def execute(self, context):
        """Bakes every frame at once (scripts, background Blender)."""
        import fraccloth

        job = None
        try:
            job = self._start(context)
            while not job.step():
                pass
        except (fraccloth.Error, ValueError) as e:
            return self._fail(job, e)
        self.report({"INFO"}, f"fraccloth: baked {job.frames} frames to {job.path}")
        return {"FINISHED"}

    def invoke(self, context, event):
        """From the interface: a frame per timer tick, progress on the cursor and in the status
        bar, Esc cancels."""
        import fraccloth

        if context.window is None or bpy.app.background:
            return self.execute(context)
        try:
            self._job = self._start(context)
        except (fraccloth.Error, ValueError) as e:
            return self._fail(None, e)
        wm = context.window_manager
        wm.progress_begin(0, self._job.frames)
        self._timer = wm.event_timer_add(0.001, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()
        context.workspace.status_text_set(None)

    def modal(self, context, event):
        import fraccloth

        job = self._job
        if event.type == "ESC":
            self._end(context)
            job.cancel()
            self.report({"WARNING"}, "fraccloth: bake cancelled; no cache written")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"RUNNING_MODAL"}
        try:
            finished = job.step()
        except (fraccloth.Error, ValueError) as e:
            self._end(context)
            return self._fail(job, e)
        context.window_manager.progress_update(job.done)
        context.workspace.status_text_set(f"fraccloth: baking frame {job.done} of {job.frames} (Esc cancels)")
        if finished:
            self._end(context)
            self.report({"INFO"}, f"fraccloth: baked {job.frames} frames to {job.path}")
            return {"FINISHED"}
        return {"RUNNING_MODAL"}


def free_bake(obj):
    """Removes `obj`'s baked cache: its fraccloth Mesh Cache modifier and the file it plays.
    Returns the paths removed."""
    removed = []
    for m in list(obj.modifiers):
        if m.type == "MESH_CACHE" and m.name == "fraccloth":
            path = bpy.path.abspath(m.filepath)
            obj.modifiers.remove(m)
            if path and os.path.exists(path):
                os.remove(path)
                removed.append(path)
    return removed


class FRACCLOTH_OT_free_bake(bpy.types.Operator):
    """Remove the active mesh's underwater bake: its cache modifier and cache file"""

    bl_idname = "fraccloth.free_bake"
    bl_label = "Free bake"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        o = context.active_object
        return o is not None and any(m.type == "MESH_CACHE" and m.name == "fraccloth" for m in o.modifiers)

    def execute(self, context):
        removed = free_bake(context.active_object)
        self.report({"INFO"}, f"fraccloth: bake freed ({', '.join(removed) or 'no file on disk'})")
        return {"FINISHED"}


class FRACCLOTH_PT_panel(bpy.types.Panel):
    bl_label = "fraccloth (underwater cloth)"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "physics"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH"

    def draw(self, context):
        s = context.object.fraccloth
        layout = self.layout
        layout.prop(s, "preset")
        layout.prop(s, "pin_group")
        for title, names in (
            ("Cloth", ("mass_per_area", "cloth_density", "stretch_stiffness", "shear_stiffness", "bend_stiffness",
                       "bend_spacing", "damping_mode", "spring_damping")),
            ("Water", ("water_density", "entrained_mass", "added_mass", "coarse_added_mass", "coarse_length", "form_drag",
                       "form_drag_scale", "skin_drag", "skin_drag_unsteady", "skin_drag_memory", "history_drag",
                       "viscous_drag", "normal_drag", "current")),
            ("Colliders", ("collider_shape", "friction", "collision_margin", "self_collision", "self_collision_spacings",
                           "self_friction")),
            ("Solver", ("history", "integrator", "auto_step", "time_step")),
            ("Cache", ("use_scene_range", "frame_start", "frame_end", "cache_format", "cache_path")),
        ):
            box = layout.box()
            box.label(text=title)
            for name in names:
                row = box.row()
                row.prop(s, name)
                if name == "time_step":
                    row.enabled = not s.auto_step
                if name in ("frame_start", "frame_end"):
                    row.enabled = not s.use_scene_range
            if title == "Colliders":
                box.label(text="Colliders: mesh objects with Collision physics, and meshes selected with the cloth")
        box = layout.box()
        box.label(text="As a collider of another fraccloth cloth")
        for own, value in (("collider_own_friction", "collider_friction"), ("collider_own_margin", "collider_margin")):
            row = box.row()
            row.prop(s, own)
            sub = row.row()
            sub.prop(s, value)
            sub.enabled = getattr(s, own)
        row = layout.row()
        row.operator(FRACCLOTH_OT_bake.bl_idname)
        row.operator(FRACCLOTH_OT_free_bake.bl_idname)


_classes = (FracclothSettings, FRACCLOTH_OT_bake, FRACCLOTH_OT_free_bake, FRACCLOTH_PT_panel)


def register():
    for c in _classes:
        bpy.utils.register_class(c)
    bpy.types.Object.fraccloth = bpy.props.PointerProperty(type=FracclothSettings)


def unregister():
    del bpy.types.Object.fraccloth
    for c in reversed(_classes):
        bpy.utils.unregister_class(c)
