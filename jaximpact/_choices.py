"""A name that is not in its table (a law, a tangential law, an engine): the one-line message
that lists the table, with the nearest names first, so `hertz` or `Hunt-Crossley` tells the
user what to type instead of only that it is wrong."""

import difflib


def plain_name(name: str) -> str:
    """A name as the tables write it: lower case, `_` for hyphens and spaces."""
    return str(name).strip().lower().replace("-", "_").replace(" ", "_")


def nearest_names(name, choices) -> list[str]:
    """The names of `choices` a mistyped `name` most likely meant: the same name but for
    case, hyphens or spaces; the names it begins; then the closest spellings (difflib)."""
    plain = plain_name(name)
    by_plain = {plain_name(choice): choice for choice in choices}
    if plain in by_plain:
        return [by_plain[plain]]
    starting = [choice for key, choice in by_plain.items() if plain and key.startswith(plain)]
    if starting:
        return starting
    close = difflib.get_close_matches(plain, list(by_plain), n=3, cutoff=0.6)
    return [by_plain[key] for key in close]


def unknown_name(kind: str, name, choices, also: str = "") -> str:
    """`unknown law 'hertz' (did you mean hertz_viscous, hertz_modified or hertz_rate?);
    choose one of: ...` (`also`: a further choice, as `or all`)."""
    nearest = nearest_names(name, choices)
    hint = ""
    if nearest:
        said = nearest[0] if len(nearest) == 1 else ", ".join(nearest[:-1]) + " or " + nearest[-1]
        hint = f" (did you mean {said}?)"
    listed = ", ".join(choices) + (f", or {also}" if also else "")
    return f"unknown {kind} {name!r}{hint}; choose one of: {listed}"
