"""An option that does not apply to the route a command takes is refused in one line
naming it and its route, never accepted and ignored (each command's table ``APPLIES``,
:mod:`dynid.cli.applies`); the library's typed options refuse the same where they can
tell a given value from a default."""

from __future__ import annotations

from pathlib import Path

import pytest

from dynid.cli.__main__ import build_parser, main
from dynid.cli.applies import given_options
from dynid.exceptions import OptionError
from dynid.io.robot_file import load_robot
from dynid.model.builtin import builtin_robot
from dynid.workflows.prior import load_prior
from dynid.workflows.retrieve import RetrieveOptions

#: (argv with {d} for a scratch folder, the start of the one error line).
REFUSED = [
    ("retrieve --model {d}/m.json --robot fr3", "--robot applies to --static"),
    (
        "retrieve --model {d}/m.json --base nonexistent --tip nolink",
        "--base applies to a URDF --robot only",
    ),
    (
        "retrieve --model {d}/m.json --prior panda --prior-base x",
        "--prior-base applies to a URDF --prior only",
    ),
    ("retrieve --model {d}/m.json --seed 7", "--seed applies to --method penalty only"),
    ("retrieve --model {d}/m.json --seed 0", "--seed applies to --method penalty only"),
    (
        "retrieve --model {d}/m.json --total-mass 16,20 --no-total-mass",
        "--total-mass sets the band --no-total-mass drops",
    ),
    (
        "retrieve --model {d}/m.json --method penalty --prior-weight 3",
        "--prior-weight applies to --method sdp only",
    ),
    (
        "identify --robot panda --data {d}/s.csv --base nonexistent",
        "--base applies to a URDF --robot only",
    ),
    (
        "identify --robot panda --data {d}/s.csv --consistent --prior-tip x",
        "--prior-tip applies to a URDF --prior only",
    ),
    ("fk --robot panda --base nonexistent --tip nolink", "--base applies to a URDF --robot only"),
    ("jacobian --robot panda --tip nolink", "--tip applies to a URDF --robot only"),
    (
        "friction --model {d}/m.json --data {d}/l.csv --base x",
        "--base applies to a URDF --robot only",
    ),
    (
        "validate --model {d}/m.json --data {d}/l.csv --base x",
        "--base applies to a URDF --robot or --params only",
    ),
    (
        "simulate --trajectory sinusoid --harmonics 3 --base-freq 0.3",
        "--harmonics applies to --trajectory fourier only",
    ),
    (
        "simulate --trajectory fourier --amplitudes 1,1,1,1,1,1,1",
        "--amplitudes applies to --trajectory sinusoid only",
    ),
    (
        "simulate --trajectory {d}/t.csv --q0 0,0,0,0,0,0,0",
        "--q0 applies to --trajectory sinusoid or fourier",
    ),
    (
        "export --params panda --out {d}/j.urdf --merged keep",
        "--merged applies to --urdf-template only",
    ),
    (
        "export --params panda --out {d}/k.xml --all-frames",
        "--all-frames applies to a URDF export without",
    ),
]


@pytest.mark.parametrize(("argv", "said"), REFUSED, ids=[a for a, _ in REFUSED])
def test_an_option_off_the_route_is_refused_in_one_line(tmp_path, capsys, argv, said):
    args = argv.format(d=tmp_path).split()
    if args[0] == "simulate":
        args += ["--out", str(tmp_path / "x.csv")]
    elif args[0] in ("retrieve", "identify", "friction", "validate"):
        args += ["--out", str(tmp_path / "out")]
    assert main(args) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith(f"dynid {args[0]}: error: {said}"), err[0]
    assert "leave it out" in err[0] or "give one of them" in err[0]
    assert not any(p.name.startswith(("out", "x.", "j.", "k.")) for p in tmp_path.iterdir())


def test_given_options_are_those_typed_not_the_defaults():
    parser = build_parser(("simulate",))
    argv = ["simulate", "--trajectory", "fourier", "--harm", "3", "--seed", "0", "--out", "x.csv"]
    assert given_options(parser, argv) == {"trajectory", "harmonics", "seed", "out"}


def test_an_option_on_its_route_is_taken(tmp_path, capsys):
    out = tmp_path / "f.csv"
    argv = ["simulate", "--trajectory", "fourier", "--harmonics", "2", "--base-freq", "0.5"]
    assert main([*argv, "--duration", "0.2", "--rate", "100", "--out", str(out), "-q"]) == 0
    assert out.is_file()
    argv = ["export", "--params", "panda", "--out", str(tmp_path / "a.urdf"), "--all-frames"]
    assert main(argv) == 0
    assert (tmp_path / "a.urdf").is_file()


def test_the_library_refuses_alike():
    with pytest.raises(OptionError) as exc:
        RetrieveOptions(total_mass=(16.0, 20.0), total_mass_band=False)
    assert exc.value.field == "total_mass"
    with pytest.raises(OptionError) as exc:
        RetrieveOptions(method="penalty", prior_weight=3.0)
    assert exc.value.field == "prior_weight"
    with pytest.raises(OptionError):  # the penalty method takes no prior, nor its weight
        RetrieveOptions(method="penalty", prior="panda", prior_weight=3.0)
    RetrieveOptions(prior_weight=3.0)  # the convex method's generic prior: taken
    for kw, field in (
        ({"base": "x"}, "base"),
        ({"tip": "y"}, "tip"),
        ({"snap_angles": True}, "snap_angles"),
    ):
        with pytest.raises(OptionError) as exc:
            load_robot("panda", **kw)
        assert exc.value.field == field
    panda = builtin_robot("panda")
    for spec in ("panda", None, Path("prior.toml")):
        with pytest.raises(OptionError) as exc:
            load_prior(spec, panda, base="x")
        assert exc.value.field == "prior_base"
