"""Writes principled_reference.inc: Mitsuba 3's own eval, pdf and sample of its `principled` and
`principledthin` BSDFs for the
configurations that mitsuba_reference_test.cpp builds, in both transport modes, from outside and inside.

Run with the Python that has the mitsuba package (scripts/test.sh installs it in .venv):
    .venv/bin/python tests/materials/generate_principled_reference.py > tests/materials/principled_reference.inc
"""
import mitsuba as mi

mi.set_variant("scalar_rgb")

# Names and parameters; the C++ test builds the same (make_bsdfs in mitsuba_reference_test.cpp).
CONFIGS = {
    "principled_default": {},
    "principled_metal_aniso": {"base_color": {"type": "rgb", "value": [0.9, 0.6, 0.3]}, "metallic": 0.8,
                               "roughness": 0.4, "anisotropic": 0.6, "spec_tint": 0.3},
    "principled_trans": {"base_color": {"type": "rgb", "value": [0.7, 0.8, 0.9]}, "spec_trans": 0.7,
                         "roughness": 0.3, "eta": 1.45},
    "principled_coat_sheen": {"base_color": {"type": "rgb", "value": [0.2, 0.4, 0.6]}, "clearcoat": 0.8,
                              "clearcoat_gloss": 0.6, "sheen": 0.7, "sheen_tint": 0.4, "flatness": 0.3,
                              "roughness": 0.7, "specular": 0.3},
    # Mitsuba's documentation example: every lobe.
    "principled_everything": {"base_color": {"type": "rgb", "value": [1.0, 1.0, 1.0]}, "metallic": 0.7,
                              "specular": 0.6, "roughness": 0.2, "spec_tint": 0.4, "anisotropic": 0.5,
                              "sheen": 0.3, "sheen_tint": 0.2, "clearcoat": 0.6, "clearcoat_gloss": 0.3,
                              "spec_trans": 0.4},
}


# principledthin's: name -> parameters.
THIN_CONFIGS = {
    "principledthin_default": {},
    "principledthin_trans": {"base_color": {"type": "rgb", "value": [0.7, 0.8, 0.9]}, "spec_trans": 0.7,
                             "roughness": 0.35, "eta": 1.4, "spec_tint": 0.3},
    "principledthin_difftrans_sheen": {"base_color": {"type": "rgb", "value": [0.3, 0.6, 0.2]}, "diff_trans": 1.2,
                                       "sheen": 0.6, "sheen_tint": 0.5, "flatness": 0.4, "roughness": 0.6},
    "principledthin_everything": {"base_color": {"type": "rgb", "value": [0.9, 0.5, 0.4]}, "spec_trans": 0.4,
                                  "diff_trans": 0.6, "anisotropic": 0.5, "roughness": 0.3, "eta": 1.3,
                                  "spec_tint": 0.2, "sheen": 0.3, "flatness": 0.2},
}


def unit(*v):
    return mi.ScalarVector3f(*v) / mi.ScalarFloat(sum(x * x for x in v) ** 0.5)


WIS = [unit(0.3, -0.2, 0.8), unit(-0.7, 0.1, 0.3), unit(0.1, 0.05, -0.9), unit(0.6, -0.3, -0.45)]
WOS = [unit(-0.2, 0.3, 0.9), unit(0.5, 0.5, 0.4), unit(-0.1, 0.0, 1.0), unit(0.3, -0.1, -0.95),
       unit(-0.5, 0.2, -0.7), unit(-0.9, 0.1, 0.2)]
SAMPLES = [(0.05, (0.2, 0.7)), (0.21, (0.6, 0.1)), (0.37, (0.9, 0.95)), (0.52, (0.3, 0.4)),
           (0.66, (0.75, 0.5)), (0.81, (0.1, 0.85)), (0.97, (0.45, 0.25))]
# u1 stays off the lobes' probability boundaries: on one (0.2 with principledthin_everything's
# spec_trans 0.4) a one-ulp difference in a parameter's value picks the neighbouring lobe.


def f(x):
    s = f"{float(x):.8g}"
    if not any(c in s for c in ".en"):  # a C++ float literal needs a point or an exponent
        s += "."
    return s + "f"


def vec(v):
    return "{" + ", ".join(f(x) for x in v) + "}"


def print_references(script, bsdfs, modes=("Radiance", "Importance"), wis=WIS, wos=WOS, samples=SAMPLES):
    """Prints the .inc lines for (name, plugin, parameters) triples: eval, pdf and sample at every query
    (each incident direction with each outgoing one and each pair of random numbers), in the given modes."""
    print("// Reference values generated with Mitsuba %s (pip package, scalar_rgb variant) by"
          % mi.__version__)
    print(f"// tests/materials/{script}; one line per query.")
    for name, plugin, params in bsdfs:
        bsdf = mi.load_dict({"type": plugin, **params})
        for mode_name in modes:
            ctx = mi.BSDFContext(getattr(mi.TransportMode, mode_name))
            for wi in wis:
                si = mi.SurfaceInteraction3f()
                si.wi = wi
                head = f'    {{"{name}", TransportMode::{mode_name}, {vec(wi)}, '
                for wo in wos:
                    value = bsdf.eval(ctx, si, wo)
                    pdf = bsdf.pdf(ctx, si, wo)
                    print(head + f"{vec(wo)}, Eval{{{vec(value)}, {f(pdf)}}}}},")
                for u1, u2 in samples:
                    bs, weight = bsdf.sample(ctx, si, u1, mi.ScalarPoint2f(*u2))
                    print(head + f"Sample{{{f(u1)}, {vec(u2)}, {vec(bs.wo)}, {f(bs.pdf)}, {f(bs.eta)}, "
                          f"{vec(weight)}}}}},")


def main():
    print_references("generate_principled_reference.py",
                     [*((n, "principled", p) for n, p in CONFIGS.items()),
                      *((n, "principledthin", p) for n, p in THIN_CONFIGS.items())])


if __name__ == "__main__":
    main()
