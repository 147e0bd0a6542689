"""A posterior as the command line asks for it and writes it: the priors of `--prior
NAME=KIND:A:B` (`priors_from_words`), and the JSON record of a posterior with its draws
evenly thinned to `JSON_DRAWS` (`thinned_record`), what `jaximpact export --from` reads for
the engine's band."""

from .priors import parse_prior

# the draws the JSON of a posterior holds: enough for the engine's band of `export --from`
JSON_DRAWS = 200


def priors_from_words(items, flag: str = "--prior") -> dict:
    """`["c=loguniform:1e5:1e8", ...]` -> `{"c": ("loguniform", 1e5, 1e8)}` (checked by
    `parse_prior`); a one-line ValueError naming `flag` for anything else."""
    prior = {}
    for item in items:
        name, sep, spec = item.partition("=")
        parts = spec.split(":")
        if not sep or not name.strip() or len(parts) != 3:
            raise ValueError(f"{flag} {item!r} must be NAME=KIND:A:B, e.g. c=loguniform:1e5:1e8")
        name = name.strip()
        if name in prior:
            raise ValueError(f"{flag} {name} is given twice")
        try:
            prior[name] = parse_prior(name, (parts[0], parts[1], parts[2])).as_tuple()
        except ValueError as error:
            raise ValueError(f"{flag} {item!r}: {error}") from None
    return prior


def thinned_record(post, draws: int = JSON_DRAWS) -> dict:
    """`post.to_dict(samples=False)` with `draws` evenly thinned draws (`samples`, `z`) and
    `thinned` (how many, of how many); the statistics are those of all the draws."""
    record = post.to_dict(samples=False)
    rows = post.draw_indices(draws)
    record["samples"] = {k: [float(x) for x in v[rows]] for k, v in post.samples.items()}
    record["z"] = [[float(x) for x in row] for row in post.z[rows]]
    record["thinned"] = {"draws": int(len(rows)), "of": post.num_draws}
    return record
