"""The single-feature scenes of the cross-check (tools/xcheck/xcheck.py) and the glTF file
each is written as: one source for clpt (which reads glTF, docs/gltf.md) and for Blender's
glTF importer (Cycles); Mitsuba gets the same triangles as PLY files and a BSDF of its own.

Every new material or light feature adds its scene here (docs/validation.md).

A scene is a dict:
  name, what        the row's name and what it tests
  material          the glTF material of the sphere (and of the floor, when there is one)
  ext               the glTF extensions the material or lights use (for extensionsUsed);
  needs             those of them clpt must read for the scene to mean anything: while clpt
                    warns that one is ignored, the scene is reported 'unsupported'
  clpt              a clpt material body that replaces the file's materials (`mesh { file
                    ... material m }`), for features that glTF cannot say (Lambert)
  cycles            "diffuse:R,G,B": every material a Lambertian Diffuse BSDF
  mitsuba           function(mi, tex) -> Mitsuba BSDF dict, or None: no equivalent
  mitsuba_emitter   for an emissive sphere: its area emitter's radiance
  light             None or a KHR_lights_punctual light with the node's place
  background        'white' (radiance 1 everywhere), 'black' or 'env' (an equirectangular map)
  floor             a 8 x 8 floor at y = -1 under the unit sphere
  sphere            False: the floor alone (a plane), seen from the floor scenes' camera
  textures          {key: (kind, size)}: images the harness draws (base colour, normal, emission)
  notes             {peer: the known model difference for this scene}
"""
import math

# the known model differences, written once and named by the scenes below
DISNEY_DIFFUSE = ("Disney's Principled: Burley's retro-reflective diffuse, not weighted by 1 - F "
                  "(glTF: Lambert x (1 - F)); brighter toward the rim")
DISNEY_SPEC = ("Disney's specular Fresnel: the exact dielectric Fresnel of ior 1.5 "
               "(glTF: Schlick, F0 0.04), larger at oblique angles")
SEPARABLE_G = "separable Smith G1 G1 (clpt: height-correlated), darker when rough"
CY_SOLID = "Cycles' Principled transmission is solid glass: no thin walls"
CY_SPOT = "Cycles multiplies spot lights by cos theta and smoothsteps the cone"
MI_SPOT = "Mitsuba's spot falls off linearly in angle between beam_width and cutoff_angle"
MAPPED_AWAY_MI = ("normalmap evaluates its BSDF in the mapped frame as it is: 0 where the viewer is below "
                  "the mapped normal's horizon (clpt and Cycles bend such a normal back toward the geometric "
                  "one), darker")
MAPPED_AWAY_CY = ("ensure_valid_reflection bends a mapped normal that faces away from the viewer, as clpt's "
                  "bsdf_normal does")


def _rgb(v):
    return {"type": "rgb", "value": list(v)}


def _principled(base, metallic, roughness, **kw):
    d = {"type": "principled", "base_color": base if isinstance(base, dict) else _rgb(base),
         "metallic": metallic, "roughness": max(roughness, 1e-3), "specular": 0.5}
    d.update(kw)
    return d


def _gltf_mat(base=(1, 1, 1), metallic=1.0, roughness=1.0, baseColorTexture=None, **kw):
    m = {"pbrMetallicRoughness": {"baseColorFactor": list(base) + [1.0], "metallicFactor": metallic,
                                  "roughnessFactor": roughness}}
    if baseColorTexture:
        m["pbrMetallicRoughness"]["baseColorTexture"] = baseColorTexture
    m.update(kw)
    return m


ORANGE = (0.8, 0.5, 0.2)
GOLDISH = (0.9, 0.6, 0.2)
GREY = (0.7, 0.7, 0.7)


def scene_list():
    S = []

    def add(name, what, **kw):
        s = {"name": name, "what": what, "material": _gltf_mat(), "ext": [], "needs": [], "clpt": None,
             "cycles": None, "mitsuba": None, "mitsuba_emitter": None, "light": None, "background": "white",
             "floor": False, "sphere": True, "textures": {}, "notes": {}}
        s.update(kw)
        S.append(s)

    # --- materials, under a uniform white background (a furnace: what is not reflected is lost)
    add("lambert", "Lambert, albedo 0.8 0.5 0.2 (every renderer's own diffuse)",
        clpt="type diffuse albedo %g %g %g" % ORANGE, cycles="diffuse:%g,%g,%g" % ORANGE,
        mitsuba=lambda mi, t: {"type": "diffuse", "reflectance": _rgb(ORANGE)})
    add("principled-diffuse", "principled, base 0.8 0.5 0.2, metallic 0, roughness 0.5",
        material=_gltf_mat(ORANGE, 0.0, 0.5),
        mitsuba=lambda mi, t: _principled(ORANGE, 0.0, 0.5),
        notes={"mitsuba": DISNEY_DIFFUSE + "; " + DISNEY_SPEC, "cycles": DISNEY_DIFFUSE})
    add("principled-specular", "principled specular lobe alone: base black, metallic 0, roughness 0.5",
        material=_gltf_mat((0, 0, 0), 0.0, 0.5),
        mitsuba=lambda mi, t: _principled((0, 0, 0), 0.0, 0.5),
        notes={"mitsuba": DISNEY_SPEC + "; " + SEPARABLE_G,
               "cycles": "Disney's specular added without taking energy from diffuse"})
    add("conductor-rough", "metal (metallic 1), base 0.9 0.6 0.2, roughness 0.5",
        material=_gltf_mat(GOLDISH, 1.0, 0.5),
        mitsuba=lambda mi, t: _principled(GOLDISH, 1.0, 0.5),
        notes={"mitsuba": SEPARABLE_G, "cycles": "multiple-scattering GGX off (GGX chosen by the importer)"})
    add("conductor-smooth", "metal (metallic 1), base 0.9 0.6 0.2, roughness 0 (a mirror)",
        material=_gltf_mat(GOLDISH, 1.0, 0.0),
        mitsuba=lambda mi, t: _principled(GOLDISH, 1.0, 0.0),
        notes={"mitsuba": "roughness 0.001 (Mitsuba's principled has no exact mirror)",
               "cycles": "0.6% brighter with no noise: presumably Cycles' own metallic Fresnel (not traced)"})
    tr = lambda r: {"KHR_materials_transmission": {"transmissionFactor": 1.0}, "KHR_materials_ior": {"ior": 1.5}}
    add("glass-thin-smooth", "thin glass wall: glTF transmission 1, roughness 0, ior 1.5 (no volume: thin)",
        material=_gltf_mat((1, 1, 1), 0.0, 0.0, extensions=tr(0)),
        ext=["KHR_materials_transmission", "KHR_materials_ior"], needs=["KHR_materials_transmission"],
        mitsuba=lambda mi, t: {"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0},
        notes={"cycles": CY_SOLID})
    add("glass-thin-rough", "thin rough glass: glTF transmission 1, roughness 0.4, ior 1.5",
        material=_gltf_mat((1, 1, 1), 0.0, 0.4, extensions=tr(0.4)),
        ext=["KHR_materials_transmission", "KHR_materials_ior"], needs=["KHR_materials_transmission"],
        mitsuba=lambda mi, t: {"type": "principledthin", "base_color": _rgb((1, 1, 1)), "roughness": 0.4,
                               "spec_trans": 1.0, "eta": 1.5},
        notes={"mitsuba": "principledthin: Disney's thin-sheet model", "cycles": CY_SOLID})
    add("glass-solid-smooth", "solid glass, ior 1.5, smooth (clpt: its dielectric; glTF via volume below)",
        material=_gltf_mat((1, 1, 1), 0.0, 0.0, extensions=tr(0)),
        ext=["KHR_materials_transmission", "KHR_materials_ior"],
        clpt="type dielectric ior 1.5 roughness 0",
        mitsuba=lambda mi, t: {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0})
    add("glass-solid-rough", "solid rough glass, ior 1.5, roughness 0.4 (GGX alpha 0.16)",
        material=_gltf_mat((1, 1, 1), 0.0, 0.4, extensions=tr(0.4)),
        ext=["KHR_materials_transmission", "KHR_materials_ior"],
        clpt="type dielectric ior 1.5 roughness 0.4",
        mitsuba=lambda mi, t: {"type": "roughdielectric", "distribution": "ggx", "alpha": 0.16,
                               "int_ior": 1.5, "ext_ior": 1.0},
        notes={"mitsuba": SEPARABLE_G,
               "cycles": "glTF's principled through the importer (clpt: its dielectric): Cycles' Principled "
                         "glass, darker than a plain GGX dielectric"})
    vol = tr(0)
    vol["KHR_materials_volume"] = {"thicknessFactor": 2.0, "attenuationColor": [0.9, 0.5, 0.3],
                                   "attenuationDistance": 1.0}
    sig = [-math.log(c) for c in (0.9, 0.5, 0.3)]
    add("volume", "KHR_materials_volume: solid glass absorbing to 0.9 0.5 0.3 per unit length",
        material=_gltf_mat((1, 1, 1), 0.0, 0.0, extensions=vol),
        ext=["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"],
        needs=["KHR_materials_volume"],
        mitsuba=lambda mi, t: {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0},
        # Mitsuba reads an RGB value as a reflectance (at most 1): the largest coefficient
        # goes into the medium's scale
        mitsuba_interior={"type": "homogeneous", "albedo": 0.0, "scale": max(sig),
                          "sigma_t": _rgb([x / max(sig) for x in sig])},
        notes={"mitsuba": "a homogeneous absorbing medium, sigma_t = -ln(colour) / distance",
               "cycles": "the importer makes a Volume Absorption of density 1/distance: "
               "sigma_a = (1 - colour) / distance, not glTF's -ln(colour) / distance"})
    add("clearcoat", "clearcoat 1, clearcoat roughness 0.1 over principled 0.8 0.5 0.2, roughness 0.5",
        material=_gltf_mat(ORANGE, 0.0, 0.5, extensions={
            "KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatRoughnessFactor": 0.1}}),
        ext=["KHR_materials_clearcoat"], needs=["KHR_materials_clearcoat"],
        mitsuba=lambda mi, t: _principled(ORANGE, 0.0, 0.5, clearcoat=1.0, clearcoat_gloss=0.9),
        notes={"mitsuba": "Disney clearcoat: GTR1 lobe at a quarter weight, fixed ior 1.5; " + DISNEY_DIFFUSE,
               "cycles": "Disney clearcoat (GTR1, a quarter weight); " + DISNEY_DIFFUSE})
    add("sheen", "KHR_materials_sheen: colour 1 1 1, roughness 0.5, over base 0.2 0.2 0.6, roughness 0.8",
        material=_gltf_mat((0.2, 0.2, 0.6), 0.0, 0.8, extensions={
            "KHR_materials_sheen": {"sheenColorFactor": [1.0, 1.0, 1.0], "sheenRoughnessFactor": 0.5}}),
        ext=["KHR_materials_sheen"], needs=["KHR_materials_sheen"],
        mitsuba=lambda mi, t: _principled((0.2, 0.2, 0.6), 0.0, 0.8, sheen=1.0, sheen_tint=0.0),
        notes={"mitsuba": "Disney sheen (Schlick-weighted grazing term), not glTF's Charlie lobe",
               "cycles": "the importer adds a Velvet BSDF (sigma = sheenRoughness, colour sheenColor) to the "
               "Principled with an Add Shader: sheen on top of the base's full energy, not layered"})
    add("specular", "KHR_materials_specular: specularFactor 0.5 (F0 0.02), base black, roughness 0.5",
        material=_gltf_mat((0, 0, 0), 0.0, 0.5, extensions={
            "KHR_materials_specular": {"specularFactor": 0.5, "specularColorFactor": [1.0, 1.0, 1.0]}}),
        ext=["KHR_materials_specular"], needs=["KHR_materials_specular"],
        mitsuba=lambda mi, t: _principled((0, 0, 0), 0.0, 0.5, specular=0.25),
        notes={"mitsuba": "specular 0.25 (F0 0.02 as an ior); " + DISNEY_SPEC,
               "cycles": "the importer sets Principled's Specular to 0.25 (Disney F0 = 0.08 x Specular); "
               "Disney's specular added without taking energy from diffuse"})
    # --- participating media (docs/media.md): a sphere of a homogeneous medium, its
    # boundary no surface (clpt's `material none`, Mitsuba's null BSDF) or glass. glTF has
    # no scattering media, so Cycles (through its importer) has no equivalent.
    def medium(sa, ss, g):
        st = [a + b for a, b in zip(sa, ss)]
        top = max(st)
        clpt = "type homogeneous sigma_a %g %g %g sigma_s %g %g %g g %g" % (tuple(sa) + tuple(ss) + (g,))
        # Mitsuba reads an RGB value as a reflectance (at most 1): sigma_t's largest
        # channel goes into the scale, as for the volume scene
        mi_med = {"type": "homogeneous", "albedo": _rgb([b / t for b, t in zip(ss, st)]),
                  "sigma_t": _rgb([t / top for t in st]), "scale": top, "phase": {"type": "hg", "g": g}}
        return clpt, mi_med
    med = dict(material=_gltf_mat((1, 1, 1), 0.0, 1.0), no_cycles=True,
               notes={"cycles": "no equivalent: glTF has no scattering media"})
    c, m = medium((0.5, 0.5, 0.5), (1.5, 1.5, 1.5), 0.5)
    add("medium", "a sphere of fog (sigma_a 0.5, sigma_s 1.5, g 0.5) behind a boundary that is no surface",
        clpt_medium=c, clpt_mesh="material none interior fog",
        mitsuba=lambda mi, t: {"type": "null"}, mitsuba_interior=m, **med)
    c, m = medium((0.2, 0.1, 0.05), (0.5, 1.0, 2.0), -0.3)
    add("medium-chromatic", "chromatic medium: sigma_a 0.2 0.1 0.05, sigma_s 0.5 1 2, g -0.3",
        clpt_medium=c, clpt_mesh="material none interior fog",
        mitsuba=lambda mi, t: {"type": "null"}, mitsuba_interior=m, **med)
    c, m = medium((0.3, 0.2, 0.1), (1.0, 1.0, 1.0), 0.7)
    add("medium-glass", "a forward-scattering medium (sigma_a 0.3 0.2 0.1, sigma_s 1, g 0.7) inside glass, "
        "ior 1.5", clpt_medium=c, clpt_mesh="material m interior fog", clpt="type dielectric ior 1.5",
        mitsuba=lambda mi, t: {"type": "dielectric", "int_ior": 1.5, "ext_ior": 1.0}, mitsuba_interior=m, **med)
    c, m = medium((0.2, 0.1, 0.05), (0.5, 1.0, 2.0), 0.3)
    add("medium-env", "the chromatic medium (g 0.3) under courtyard.hdr: light samples from inside the medium",
        clpt_medium=c, clpt_mesh="material none interior fog", background="env",
        mitsuba=lambda mi, t: {"type": "null"}, mitsuba_interior=m,
        **dict(med, notes={"cycles": "no equivalent: glTF has no scattering media",
                           "mitsuba": "bilinear map lookup (clpt: nearest texel)"}))
    # a heterogeneous medium: a 16^3 density grid over the sphere's box [-1, 1]^3 (clpt's
    # `type grid`, Mitsuba's gridvolume; both interpolate between cell centres and clamp
    # at the border), chromatic extinction, delta and ratio tracking against volpath's
    def grid_density(n=16):
        d = []
        for k in range(n):
            for j in range(n):
                for i in range(n):
                    x, y, z = ((c + 0.5) / n * 2.0 - 1.0 for c in (i, j, k))
                    d.append(0.5 + 0.5 * math.sin(3.0 * x) * math.cos(2.0 * y) * math.sin(2.5 * z + 0.5))
        return n, d

    def grid_medium(sa, ss, g):
        n, d = grid_density()
        st = [a + b for a, b in zip(sa, ss)]
        top = max(st)
        clpt = ("type grid sigma_a %g %g %g sigma_s %g %g %g g %g size %d %d %d min -1 -1 -1 max 1 1 1 data [ %s ]" %
                (tuple(sa) + tuple(ss) + (g, n, n, n, " ".join("%.6g" % v for v in d))))

        def mitsuba(mi):
            import numpy as np
            grid = np.array(d, dtype=np.float32).reshape(n, n, n, 1) * np.array([t / top for t in st], np.float32)
            to_world = mi.ScalarTransform4f().translate([-1.0, -1.0, -1.0]) @ mi.ScalarTransform4f().scale(2.0)
            return {"type": "heterogeneous", "scale": top,
                    "sigma_t": {"type": "gridvolume", "grid": mi.VolumeGrid(grid), "to_world": to_world},
                    "albedo": _rgb([b / t for b, t in zip(ss, st)]), "phase": {"type": "hg", "g": g}}
        return clpt, mitsuba
    c, m = grid_medium((0.3, 0.2, 0.1), (1.0, 2.0, 3.0), 0.4)
    add("medium-grid", "a heterogeneous medium: a 16^3 density grid (0 .. 1) times sigma_a 0.3 0.2 0.1, "
        "sigma_s 1 2 3, g 0.4, behind a boundary that is no surface",
        clpt_medium=c, clpt_mesh="material none interior fog",
        mitsuba=lambda mi, t: {"type": "null"}, mitsuba_interior=m, **med)
    # --- emission and textures, black background
    add("emission", "emissive 1 0.5 0.25 x strength 2 (KHR_materials_emissive_strength), black base",
        material=_gltf_mat((0, 0, 0), 0.0, 1.0, emissiveFactor=[1.0, 0.5, 0.25],
                           extensions={"KHR_materials_emissive_strength": {"emissiveStrength": 2.0}}),
        ext=["KHR_materials_emissive_strength"], needs=["KHR_materials_emissive_strength"],
        background="black",
        mitsuba=lambda mi, t: {"type": "diffuse", "reflectance": _rgb((0, 0, 0))},
        mitsuba_emitter=(2.0, 1.0, 0.5))
    add("texture-emission", "emissive texture (sRGB, NEAREST): the image itself, no BSDF involved",
        material=_gltf_mat((0, 0, 0), 0.0, 1.0, emissiveFactor=[1.0, 1.0, 1.0], emissiveTexture="emissive"),
        background="black", textures={"emissive": ("checker", 64)},
        mitsuba=lambda mi, t: {"type": "diffuse", "reflectance": _rgb((0, 0, 0))},
        mitsuba_emitter="emissive")
    add("texture-base", "base colour texture (sRGB, NEAREST), metallic 0, roughness 1",
        material=_gltf_mat((1, 1, 1), 0.0, 1.0, baseColorTexture="base"), textures={"base": ("checker", 64)},
        mitsuba=lambda mi, t: _principled(t["base"], 0.0, 1.0),
        notes={"mitsuba": DISNEY_DIFFUSE, "cycles": DISNEY_DIFFUSE})
    # --- lights: a Lambertian sphere (0.7 grey) on a floor of the same, black background
    lam = dict(clpt="type diffuse albedo %g %g %g" % GREY, cycles="diffuse:%g,%g,%g" % GREY,
               mitsuba=lambda mi, t: {"type": "diffuse", "reflectance": _rgb(GREY)},
               background="black", floor=True, ext=["KHR_lights_punctual"], needs=["KHR_lights_punctual"])
    add("light-point", "point light, 683 x 8 cd (8 W/sr) white, at (2, 3, 2)",
        light={"type": "point", "color": [1, 1, 1], "intensity": 683.0 * 8, "at": (2.0, 3.0, 2.0)}, **lam)
    add("light-spot", "spot light, 683 x 20 cd, at (0, 3.5, 1) down, inner 15, outer 30 degrees",
        light={"type": "spot", "color": [1, 1, 1], "intensity": 683.0 * 20, "at": (0.0, 3.5, 1.0),
               "spot": {"innerConeAngle": math.radians(15), "outerConeAngle": math.radians(30)}},
        notes={"mitsuba": MI_SPOT, "cycles": CY_SPOT}, **lam)
    add("light-directional", "directional light, 683 x 2 lux (2 W/m^2), from (1, 2, 1)",
        light={"type": "directional", "color": [1, 1, 1], "intensity": 683.0 * 2, "dir": (-1.0, -2.0, -1.0)},
        **lam)
    add("normal-map", "normal map (bumps in u and v, TANGENT given), principled 0.8 grey, roughness 1, "
        "directional light", material=_gltf_mat((0.8, 0.8, 0.8), 0.0, 1.0, normalTexture="normal"),
        textures={"normal": ("bumps", 128)}, background="black", ext=["KHR_lights_punctual"],
        needs=["KHR_lights_punctual"],
        light={"type": "directional", "color": [1, 1, 1], "intensity": 683.0 * 3, "dir": (-1.0, -0.5, -1.0)},
        mitsuba=lambda mi, t: {"type": "normalmap", "normalmap": t["normal"],
                               "bsdf": _principled((0.8, 0.8, 0.8), 0.0, 1.0)},
        notes={"mitsuba": DISNEY_DIFFUSE + "; tangent frame from its own uv derivatives",
               "cycles": DISNEY_DIFFUSE + "; MikkTSpace tangents from the uvs"})
    # the same normal map on a Lambertian base, in every renderer: glTF's principled with
    # KHR_materials_specular's specularFactor 0 (no specular lobe, no Fresnel taken from
    # the diffuse: Lambert), Mitsuba's normalmap over its diffuse, Cycles' Diffuse BSDF fed
    # by the importer's Normal Map node. Without the Disney diffuse of the normal-map row,
    # what is left is the normal mapping: the tangent frame, and what each renderer does
    # where the mapped normal faces away from the viewer (MAPPED_AWAY_*).
    lam_nm = dict(material=_gltf_mat((0.8, 0.8, 0.8), 0.0, 1.0, normalTexture="normal", extensions={
                      "KHR_materials_specular": {"specularFactor": 0.0}}),
                  textures={"normal": ("bumps", 128)}, background="black",
                  ext=["KHR_lights_punctual", "KHR_materials_specular"],
                  needs=["KHR_lights_punctual", "KHR_materials_specular"], cycles="diffuse:0.8,0.8,0.8",
                  mitsuba=lambda mi, t: {"type": "normalmap", "normalmap": t["normal"],
                                         "bsdf": {"type": "diffuse", "reflectance": _rgb((0.8, 0.8, 0.8))}},
                  notes={"mitsuba": MAPPED_AWAY_MI + "; tangent frame from its own uv derivatives",
                         "cycles": MAPPED_AWAY_CY + "; MikkTSpace tangents from the uvs"})
    add("normal-map-lambert", "the normal-map row's bumps on a Lambertian 0.8 grey (glTF specularFactor 0), "
        "directional light", light={"type": "directional", "color": [1, 1, 1], "intensity": 683.0 * 3,
                                    "dir": (-1.0, -0.5, -1.0)}, **lam_nm)
    add("normal-map-plane", "a plane of domes: the bumps' normal map on the 8 x 8 floor alone (Lambertian 0.8 "
        "grey), seen from 17 to 40 degrees above it, lit from behind the domes (issue 39's black rims)",
        floor=True, sphere=False,
        light={"type": "directional", "color": [1, 1, 1], "intensity": 683.0 * 3, "dir": (0.3, -0.8, 1.0)},
        **lam_nm)
    # --- environment map
    add("env-lambert", "Lambert 0.8 0.5 0.2 under courtyard.hdr",
        clpt="type diffuse albedo %g %g %g" % ORANGE, cycles="diffuse:%g,%g,%g" % ORANGE,
        mitsuba=lambda mi, t: {"type": "diffuse", "reflectance": _rgb(ORANGE)}, background="env",
        notes={"mitsuba": "bilinear map lookup (clpt and Cycles: nearest texel)"})
    add("env-conductor", "metal 0.9 0.6 0.2, roughness 0.3, under courtyard.hdr",
        material=_gltf_mat(GOLDISH, 1.0, 0.3), background="env",
        mitsuba=lambda mi, t: _principled(GOLDISH, 1.0, 0.3),
        notes={"mitsuba": SEPARABLE_G + "; bilinear map lookup"})
    return S
