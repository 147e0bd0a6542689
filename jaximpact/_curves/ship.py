"""Rebuild the shipped curves: `python -m jaximpact._curves.ship [--all | NAME ...]`.

Builds every shape of `store.SHIPPED` that the shipped file lacks (all of them with
`--all`, and those named, e.g. `n=1.5,p=0,force`), writing the file after each one, so an
interrupted run keeps what it built.
`python docs/similarity_accuracy.py` then checks them against independent references.
"""

import sys

import jax


def main(argv=None):
    jax.config.update("jax_enable_x64", True)
    from . import store
    from .build import build_curves

    argv = sys.argv[1:] if argv is None else argv
    done = (
        {} if "--all" in argv or not store.SHIPPED_FILE.exists() else store.load(store.SHIPPED_FILE)
    )
    done = {key: curves for key, curves in done.items() if key.name not in argv}
    for key in store.SHIPPED:
        if key in done:
            continue
        curves = build_curves(key, max_steps=400_000)
        done[key] = curves
        store.save([done[k] for k in store.SHIPPED if k in done], store.SHIPPED_FILE)
        print(
            f"{key.name}: {len(curves.breaks) - 1} pieces up to beta = {curves.beta_max:.4g}, "
            f"capture {curves.capture}, largest tail {curves.tail.max():.1e}",
            flush=True,
        )
    print(f"written {store.SHIPPED_FILE}")


if __name__ == "__main__":
    main()
