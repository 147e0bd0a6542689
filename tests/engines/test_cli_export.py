"""`jaximpact export` and `jaximpact engine-e`: bad input is one line with exit status 2,
and what export writes, engine-e reads back."""

import json
import re

import pytest

from jaximpact._cli import main


@pytest.mark.parametrize(
    "argv, match",
    [
        (
            ["export", "--engine", "bullet", "--e", "0.5", "--T", "1e-3", "--v0", "1"],
            "unknown engine",
        ),
        (["export", "--engine", "lammps", "--e", "0.5", "--T", "1e-3", "--v0", "1"], "radius"),
        (["export", "--engine", "mujoco", "--e", "1.5", "--T", "1e-3", "--v0", "1"], r"\(0, 1\]"),
        (["export", "--engine", "mujoco", "--e", "0.5", "--T", "0", "--v0", "1"], "T must be"),
        (
            [
                "export",
                "--engine",
                "mujoco",
                "--e",
                "0.5",
                "--T",
                "1e-3",
                "--v0",
                "1",
                "--mass",
                "-1",
            ],
            "m must be",
        ),
        (
            [
                "export",
                "--engine",
                "lammps",
                "--e",
                "0.5",
                "--T",
                "1e-3",
                "--v0",
                "1",
                "--radius",
                "0.01",
                "--mass",
                "0.01",
                "--poisson",
                "0.5",
            ],
            r"\(-1, 0.5\)",
        ),
        (
            [
                "export",
                "--engine",
                "mujoco",
                "--law",
                "maxwell",
                "--param",
                "c=1e6",
                "b=1",
                "--e",
                "0.5",
                "--v0",
                "1",
            ],
            "not both",
        ),
        (
            [
                "engine-e",
                "--engine",
                "lammps",
                "--params",
                '{"E": -1, "coeff_restitution": 0.5}',
                "--radius",
                "0.01",
                "--mass",
                "0.01",
                "--speed",
                "1",
            ],
            "E must be",
        ),
        (["engine-e", "--engine", "drake", "--params", "{", "--speed", "1"], "not JSON"),
        (
            ["engine-e", "--engine", "mujoco", "--params", '{"solref": [NaN, 1]}', "--speed", "1"],
            "solref must be",
        ),
        (
            ["engine-e", "--engine", "yade", "--params", '{"tc": 1e-3}', "--speed", "1"],
            "needs en",
        ),
        (
            ["export", "--engine", "mujoco", "--e", "0.5", "--T", "1e-300", "--v0", "1"],
            "float64 cannot hold",
        ),
        (
            [
                "export",
                "--engine",
                "yade",
                "--e",
                "0.1",
                "--T",
                "1e-3",
                "--v0",
                "1",
                "--radius",
                "0.01",
                "--mass",
                "0.01",
            ],
            r"exp\(-2\)",
        ),
    ],
)
def test_cli_bad_input_is_one_line_with_status_2(argv, match, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("jaximpact: error:") and "\n" not in err
    assert re.search(match, err), err


def test_cli_export_json_and_engine_e_round_trip(capsys):
    """export then engine-e on the exported solref gives back the same continuous e."""
    main(
        [
            "export",
            "--engine",
            "mujoco",
            "--e",
            "0.6",
            "--T",
            "5e-3",
            "--mass",
            "0.05",
            "--v0",
            "1",
            "--json",
        ]
    )
    out = json.loads(capsys.readouterr().out)
    assert abs(out["e"] / 0.6 - 1) < 1e-3 and len(out["parameters"]["solimp"]) == 5
    params = json.dumps(
        {"solref": out["parameters"]["solref"], "timestep": out["parameters"]["timestep"]}
    )
    main(
        [
            "engine-e",
            "--engine",
            "mujoco",
            "--params",
            params,
            "--mass",
            "0.05",
            "--speed",
            "0.5",
            "1",
            "--json",
        ]
    )
    back = json.loads(capsys.readouterr().out)
    # export's e(v) is what MuJoCo's step realises (speeds 0.5 and 1 are its 3rd and 4th)
    assert back["stepped"]["e"] == pytest.approx(out["e_engine"][2:4], rel=1e-12)
    assert back["stepped"]["e"][1] == pytest.approx(out["e"], rel=1e-12)
    # and the continuous law is within the recommended step's 0.5 %
    assert back["e"] == pytest.approx(out["e_engine"][2:4], rel=5e-3)


def test_cli_yade_export_and_engine_e_round_trip(capsys):
    """export --engine yade, then engine-e on its tc, en and timestep: the stepped e is the
    export's promise, and the continuous law's e is the target."""
    main(
        [
            "export",
            "--engine",
            "yade",
            "--e",
            "0.5",
            "--T",
            "1e-3",
            "--mass",
            "0.01",
            "--v0",
            "1",
            "--radius",
            "0.01",
            "--json",
        ]
    )
    out = json.loads(capsys.readouterr().out)
    p = out["parameters"]
    params = json.dumps({"tc": p["tc"], "en": p["en"], "timestep": p["timestep"]})
    main(
        [
            "engine-e",
            "--engine",
            "yade",
            "--params",
            params,
            "--mass",
            "0.01",
            "--speed",
            "1",
            "--json",
        ]
    )
    back = json.loads(capsys.readouterr().out)
    assert back["e"][0] == pytest.approx(0.5, rel=1e-6)
    assert back["stepped"]["e"][0] == pytest.approx(out["e"], rel=1e-9)


def test_cli_export_wall(capsys):
    """--wall exports the sphere on a wall; without it, the pair (unchanged)."""
    argv = [
        "export",
        "lammps",
        "--e",
        "0.5",
        "--T",
        "5e-4",
        "--mass",
        "0.004",
        "--v0",
        "1",
        "--radius",
        "0.005",
        "--json",
    ]
    main([*argv, "--wall"])
    wall = json.loads(capsys.readouterr().out)
    assert wall["parameters"]["geometry"] == "wall" and "fix wall all wall/gran" in wall["snippet"]
    main(argv)
    pair = json.loads(capsys.readouterr().out)
    assert "geometry" not in pair["parameters"] and "wall/gran" not in pair["snippet"]
    with pytest.raises(SystemExit):
        main(
            [
                "export",
                "lammps",
                "--e",
                "0.5",
                "--T",
                "5e-4",
                "--mass",
                "0.004",
                "--v0",
                "1",
                "--wall",
            ]
        )
    assert "radius (m) of the sphere" in capsys.readouterr().err


TANGENTIAL_ARGV = [
    "--law",
    "tsuji",
    "--param",
    "c=4.2e9",
    "b=15",
    "--mass",
    "2.618e-4",
    "--v0",
    "3.9",
]


@pytest.mark.parametrize(
    "extra, message",
    [
        (
            [
                "chrono",
                "--radius",
                "2.5e-3",
                "--tangential",
                "mindlin",
                "--tparam",
                "G_star=1e10",
                "mu=0.1",
            ],
            "Chrono has no tangential export yet",
        ),
        (
            ["drake", "--tangential", "mindlin", "--tparam", "G_star=1e10", "mu=0.1"],
            "needs the sphere's radius",
        ),
        (
            ["mujoco", "--tangential", "mindlin", "--tparam", "G_star=1e10", "mu=0.1"],
            "needs the sphere's radius",
        ),
        (["lammps", "--radius", "2.5e-3", "--tparam", "mu=0.1"], "--tparam needs --tangential"),
        (
            ["lammps", "--radius", "2.5e-3", "--tangential", "mindlin", "--tparam", "mu"],
            "--tparam 'mu' must be NAME=VALUE",
        ),
    ],
)
def test_cli_export_tangential_bad_input(capsys, extra, message):
    with pytest.raises(SystemExit) as stop:
        main(["export", *extra, *TANGENTIAL_ARGV])
    out, err = capsys.readouterr()
    assert stop.value.code == 2 and out == "" and len(err.strip().splitlines()) == 1
    assert message in err


@pytest.mark.slow
def test_cli_export_tangential_to_lammps(capsys):
    """The clause in pair_coeff and fix wall/gran, and the promise from 5 to 75 degrees,
    as text and as JSON (the Python export's numbers)."""
    import jaximpact as ji

    argv = [
        "export",
        "lammps",
        *TANGENTIAL_ARGV,
        "--radius",
        "2.5e-3",
        "--wall",
        "--tangential",
        "mindlin",
        "--tparam",
        "G_star=1.35e10",
        "mu=0.092",
    ]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "tangential mindlin 1.35e+11 0 0.092" not in out  # k is 8 G*, not G*
    assert out.count("tangential mindlin 1.08e+11 0 0.092") >= 2 and "spin after" in out
    assert main([*argv, "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    tl = ji.tangential_law("mindlin", G_star=1.35e10, mu=0.092)
    x = ji.export(
        ji.law("tsuji", c=4.2e9, b=15.0),
        "lammps",
        m=2.618e-4,
        v0=3.9,
        radius=2.5e-3,
        geometry="wall",
        tangential=tl,
        curves=False,
    )
    assert data["e_t_engine"] == pytest.approx(list(x.e_t_engine), rel=1e-12)
    # every parameter of the law, the Mindlin damper beta at its default 0 included
    parameters = {"G_star": 1.35e10, "mu": 0.092, "beta": 0.0}
    assert data["tangential"] == {"name": "mindlin", "parameters": parameters}
