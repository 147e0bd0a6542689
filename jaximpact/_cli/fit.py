"""`jaximpact fit`: fit a contact law to a recorded bounce (a trajectory or impact times).

Formats read (detected from the file unless `--format` says):
- an ImageJ MTrack2 export (`Frame X1 Y1 Flag1 ...`, whitespace or commas): a video track,
  time in frames (`--frame-rate` converts it), `Y1` in pixels pointing down, the pixel scale
  fitted unless `--length-scale` gives it;
- a CSV with a header: a time column (`t`, `time`, `time_s`, ...) and a height column (`y`,
  `height`, `h`, `z`, ...) is a trajectory; a time column alone (`event_time_s`,
  `impact_time`, `t`, ...) is a list of impact times, one group per drop when the file has
  other columns that tell drops apart (`--where COLUMN=VALUE` selects some);
- plain numbers: two columns are `t y`, one column is impact times.
"""

import math
from pathlib import Path

from .._fit.recordings import parse_number, read_recording
from .._plotting import plot_bounce_fits
from .calibrate import add_posterior_arguments, posterior_options, sample_posterior
from .common import (
    CLIError,
    add_contact_arguments,
    add_free_argument,
    add_law_arguments,
    add_output_arguments,
    check_plot_path,
    command_parser,
    emit,
    free_names,
    heartbeat_meter,
    law_from_args,
)

FORMATS = ("auto", "trajectory", "impacts")


def add_fit(subparsers):
    parser = command_parser(
        subparsers,
        "fit",
        help="fit a law to a bouncing ball: a sampled trajectory or the impact times",
        description="Fit the force law --law to a ball of mass --mass (kg) bouncing on a floor, "
        "recorded in FILE either as a trajectory (time and height, e.g. a video track) or as "
        "the instants of its impacts (e.g. a microphone). Free flights are closed-form, each "
        "contact an impact solve with gravity. The law's damping is fitted (--free to choose), "
        "with the nuisance quantities of a recording: the first impact's time and speed (the "
        "drop height), and for a trajectory the floor level and, for a video, the pixel scale. "
        "Double and missed detections among impact times, and tracking glitches, are found, "
        "dropped and reported. Prints e per impact with its standard error; parameters the "
        "data cannot fix are reported as undetermined. A CSV with more columns than the "
        "times (e.g. trial, ball, height) holds one drop per distinct row of those columns: "
        "each drop is fitted on its own; impact times that go backwards within one drop are "
        "refused.",
        example="jaximpact fit impacts.csv --law hertz_rate --param c=5.5e7 b1=100 --mass 0.0415\n"
        "jaximpact fit impacts.csv --law kelvin_voigt --param c=2e6 b=5 --mass 0.0027 "
        "--where ball=pingpong --where trial=1 --drag 0.14 --json\n"
        "jaximpact fit 1-1-B-A5.csv --law kelvin_voigt --param c=2000 b=0.5 --mass 0.0055 "
        "--frame-rate 240 --plot marble.png",
    )
    parser.add_argument("file", type=Path, metavar="FILE", help="the recording (CSV or text)")
    add_law_arguments(parser)
    parser.add_argument("--mass", type=float, required=True, metavar="KG", help="mass, kg (> 0)")
    parser.add_argument(
        "--format",
        choices=FORMATS,
        default="auto",
        help="what FILE holds (default: detect it)",
    )
    add_free_argument(
        parser,
        "law parameters to fit, e.g. --free c,b1 (default: the damping; the others keep "
        "--param's values)",
    )
    add_contact_arguments(parser, gravity=9.81)
    parser.add_argument(
        "--drag",
        type=float,
        metavar="1/M",
        help="quadratic air drag k = rho Cd A / (2 m) in flight (default: none)",
    )
    parser.add_argument(
        "--fit-drag", action="store_true", help="fit the air drag, starting from --drag"
    )
    parser.add_argument(
        "--where",
        action="append",
        default=[],
        metavar="COLUMN=VALUE",
        help="keep only the rows of a CSV whose COLUMN equals VALUE (repeatable)",
    )
    parser.add_argument(
        "--frame-rate",
        type=float,
        metavar="FPS",
        help="frames per second of a track whose time is in frames (required for MTrack2)",
    )
    parser.add_argument(
        "--length-scale",
        metavar="UNITS/M",
        help="units of the height per metre (e.g. pixels per metre), or 'fit' "
        "(default: 'fit' for a video track, 1 otherwise: heights in metres)",
    )
    parser.add_argument(
        "--y-axis",
        choices=("up", "down"),
        help="direction of the height axis (default: down for a video track, up otherwise)",
    )
    parser.add_argument(
        "--sigma",
        type=float,
        metavar="NOISE",
        help="measurement noise (s for impact times, height units for a trajectory); "
        "default: estimated from the residuals",
    )
    add_posterior_arguments(parser)
    add_output_arguments(parser)
    parser.set_defaults(handler=run_fit)


# ----------------------------------------------------------------------------- reading


# ----------------------------------------------------------------------------- fitting


def _options(args, recording):
    if args.length_scale is None:
        length_scale = "fit" if recording.video else None
    elif args.length_scale == "fit":
        length_scale = "fit"
    else:
        length_scale = parse_number(args.length_scale)
        if length_scale is None or length_scale <= 0:
            raise CLIError(
                f"--length-scale must be a number > 0 or 'fit', got {args.length_scale!r}"
            )
    y_axis = args.y_axis or ("down" if recording.video else "up")
    return length_scale, y_axis


def _fit_one(law, args, recording, name, data, length_scale, y_axis):
    import numpy as np

    from .._fit.fit_bounces import fit_bounces

    common = dict(
        m=args.mass,
        free=free_names(args.free),
        g=args.gravity,
        separation=args.separation,
        drag=args.drag,
        fit_drag=args.fit_drag,
        sigma=args.sigma,
    )
    if recording.kind == "impacts":
        times = np.asarray(data, dtype=float)
        back = np.flatnonzero(np.diff(times) < 0)
        if back.size:
            i = int(back[0]) + 1
            where = "" if name == "all" else f" of {name}"
            raise CLIError(
                f"the impact times{where} go backwards at time number {i + 1} "
                f"({times[i]:.6g} s after {times[i - 1]:.6g} s): several drops in one list? "
                "add a column that tells them apart (e.g. trial; each is fitted on its own) "
                "or pick one with --where"
            )
        return fit_bounces(law, impact_times=times, **common)
    t, y = (np.asarray(a, dtype=float) for a in data)
    if recording.video and args.frame_rate is None:
        raise CLIError("a video track's time is in frames: give --frame-rate FPS")
    if args.frame_rate is not None:
        t = t / args.frame_rate
    return fit_bounces(law, t=t, y=y, length_scale=length_scale, y_axis=y_axis, **common)


def run_fit(args):
    sampling = posterior_options(args)  # before reading or fitting anything
    check_plot_path(args.plot, inputs=[args.file])
    if not (math.isfinite(args.mass) and args.mass > 0):
        raise CLIError(f"--mass must be a number > 0 kg, got {args.mass}")
    if args.fit_drag and args.drag is None:
        raise CLIError("--fit-drag needs a starting value: --drag K")
    if args.frame_rate is not None and not args.frame_rate > 0:
        raise CLIError(f"--frame-rate must be > 0, got {args.frame_rate}")
    recording = read_recording(args.file, args.format, args.where)
    law = law_from_args(args)
    length_scale, y_axis = _options(args, recording)
    from .._progress import metered

    fits = {}
    with metered(heartbeat_meter(), len(recording.groups), "fitting") as bar:
        for name, data in recording.groups.items():
            fits[name] = _fit_one(law, args, recording, name, data, length_scale, y_axis)
            bar.update(1, name[:24])
    units = "s" if recording.kind == "impacts" else ("px" if recording.video else "m")
    if args.plot is not None:
        plot_bounce_fits(args.plot, fits, trajectory=recording.kind == "trajectory")
    payload = {
        "file": str(args.file),
        "kind": recording.kind,
        "fits": {name: fit.to_dict() for name, fit in fits.items()},
    }
    posts = {}
    if sampling is not None:  # one posterior per drop
        for name, fit in fits.items():
            posts[name], payload["fits"][name]["posterior"] = sample_posterior(fit, sampling)
            if args.plot is not None:
                path = _posterior_plot_path(args.plot, name, len(fits))
                posts[name].plot(path)
                payload["fits"][name]["posterior"]["plot"] = str(path)
    if args.plot is not None:
        payload["plot"] = str(args.plot)

    def text():
        blocks = []
        for name, fit in fits.items():
            blocks.append(fit.summary(units, title=name))
            if name in posts:
                block = posts[name].summary()
                record = payload["fits"][name]["posterior"]
                if "plot" in record:
                    block += f"\n  pairs plot written to {record['plot']}"
                blocks.append(block)
        if args.plot is not None:
            blocks.append(f"plot written to {args.plot}")
        return "\n\n".join(blocks)

    emit(args, payload, text)
    return 0


def _posterior_plot_path(plot: Path, name: str, count: int) -> Path:
    """Where `--plot PATH` puts a drop's posterior pairs plot: `STEM-posterior.SUFFIX`
    beside it, with the drop's name when the file holds several."""
    import re

    tag = "" if count == 1 else "-" + re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_")
    return plot.with_name(f"{plot.stem}-posterior{tag}{plot.suffix}")
