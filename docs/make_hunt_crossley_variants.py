"""Write docs/hunt_crossley_variants.md: the restitution each published Hunt-Crossley damping
formula really gives, against the one it was asked for (`jaximpact paper` writes the same
table beside its figures).

Run: python docs/make_hunt_crossley_variants.py
"""

from pathlib import Path

import jax

jax.config.update("jax_enable_x64", True)

from jaximpact._paper.tables import hunt_crossley_variants_markdown  # noqa: E402

if __name__ == "__main__":
    text = hunt_crossley_variants_markdown()
    Path(__file__).with_name("hunt_crossley_variants.md").write_text(text)
    print(text)
