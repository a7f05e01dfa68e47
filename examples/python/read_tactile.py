"""Read the taction.covering tactile sensor from MuJoCo's official Python bindings.

Loads the plugin library, loads mjcf/scene.xml (arm, table, example object, the paper's 6x6 sensor on
the pad), moves the arm to the keyframe "touch" (the pad pressed onto the rim of the object's
cylinder), computes the sensors with mj_forward, prints the 6x6 image from sensordata and saves it as
a PNG with matplotlib.

    python examples/python/read_tactile.py [--plugin LIB] [--scene XML] [--out tactile.png]

Needs mujoco==3.17.0 and matplotlib; run `cargo xtask setup` first, which builds the plugin library
(target/release/libtaction_covering.so; `taction plugin-path` prints its absolute path).
"""

import argparse
import os
import sys

import mujoco

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--plugin",
        default=os.path.join(ROOT, "target", "release", "libtaction_covering.so"),
        help="the plugin library (default: the one `cargo xtask setup` builds)",
    )
    parser.add_argument("--scene", default=os.path.join(ROOT, "mjcf", "scene.xml"))
    parser.add_argument("--out", default="tactile.png", help="PNG to write")
    args = parser.parse_args()

    if not os.path.isfile(args.plugin):
        sys.exit(f"no plugin library at {args.plugin}: run `cargo xtask setup` first")
    mujoco.mj_loadPluginLibrary(args.plugin)
    m = mujoco.MjModel.from_xml_path(args.scene)
    d = mujoco.MjData(m)

    # The arm's joint angles that put the pad on the object, then the sensors for that state.
    mujoco.mj_resetDataKeyframe(m, d, m.key("touch").id)
    mujoco.mj_forward(m, d)

    sensor = m.sensor("tactile")
    rows = cols = int(round(sensor.dim[0] ** 0.5))  # scene.xml's sensor is square (6x6)
    image = d.sensordata[sensor.adr[0] : sensor.adr[0] + rows * cols].reshape(rows, cols)
    for row in image:
        print(" ".join(f"{v:.4f}" for v in row))

    try:
        import matplotlib
    except ImportError:
        sys.exit(f"saving {args.out} needs matplotlib (pip install matplotlib); the image is printed above")
    matplotlib.use("Agg")  # no display needed
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(3, 3))
    # Row 0 is the pad's up edge; column 0 its left edge seen from behind the pad.
    shown = ax.imshow(image, cmap="inferno", vmin=0.0, vmax=1.0)
    ax.set_title(f"taction.covering, {rows}x{cols}")
    ax.set_xticks([])
    ax.set_yticks([])
    fig.colorbar(shown, ax=ax, label="penetration / covering thickness")
    fig.tight_layout()
    fig.savefig(args.out, dpi=100)
    print(f"saved {args.out}")


if __name__ == "__main__":
    main()
