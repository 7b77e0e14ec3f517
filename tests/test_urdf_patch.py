"""URDF export that fits the user's files: template patching and the chain export's names.

Reference: Pinocchio (``buildModelFromUrdf``, CRBA, generalized gravity) on the patched
template and on the chain export; the template's own text for what must be kept.
"""

from __future__ import annotations

import re
import warnings

import numpy as np
import pytest

import dynid
from dynid.cli.__main__ import main
from dynid.exceptions import DynidWarning, ModelError
from dynid.io.export import save_robot
from dynid.io.robot.urdf import robot_from_urdf_string, save_urdf, urdf_from_robot
from dynid.io.robot.urdf_patch import patch_urdf_inertials

from conftest import pinocchio_panda_urdf, random_states, robot_data_urdf

_INERTIAL = re.compile(r"<inertial\b.*?</inertial>", re.S)
_FINGERS = ("panda_finger_joint1", "panda_finger_joint2")


def _template_chain():
    path = pinocchio_panda_urdf()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        chain = dynid.Robot.from_urdf(path, "panda_link0", "panda_hand")
    return path, chain


def _identified(chain, seed):
    """The template's chain with every body scaled by a factor in [1, 1.3] (stays consistent)."""
    rng = np.random.default_rng(seed)
    return chain.with_params(chain.phi * rng.uniform(1.0, 1.3, (chain.n, 1)))


def _pin_M_g(path, q, lock=()):
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(path))
    if lock:
        ids = [model.getJointId(name) for name in lock]
        model = pin.buildReducedModel(model, ids, pin.neutral(model))
    model.gravity.linear = np.array([0.0, 0.0, -9.80665])  # dynid's default
    data = model.createData()
    M = np.stack([pin.crba(model, data, qv) for qv in q])
    M = np.triu(M) + np.swapaxes(np.triu(M, 1), -1, -2)
    g = np.stack([pin.computeGeneralizedGravity(model, data, qv) for qv in q])
    return M, g


def test_patched_template_keeps_every_link_joint_and_mesh(tmp_path):
    """Only the chain's <inertial> elements change; links, joints, meshes, dynamics and the
    hand's and fingers' inertials stay (before, the fingers' went: a simulator drops a
    moving link without one)."""
    path, chain = _template_chain()
    text = open(path).read()
    new = _identified(chain, seed=1)
    out = save_urdf(tmp_path / "p.urdf", new, template=path, base="panda_link0", tip="panda_hand")
    patched = out.read_text()
    head, header, rest = patched.split("\n", 2)
    assert header.startswith("<!-- written by dynid") and head == text.split("\n", 1)[0]
    patched = f"{head}\n{rest}"  # without the header comment (its own test)
    inertial = re.compile(r"\s*<inertial\b.*?</inertial>", re.S)
    assert inertial.sub("", patched) == inertial.sub("", text)
    for pattern in (r'<link name="([^"]+)"', r'<joint name="([^"]+)"', r'filename="([^"]+)"'):
        assert re.findall(pattern, patched) == re.findall(pattern, text)
    assert patched.count("<dynamics") == text.count("<dynamics") > 0
    holding = re.compile(r'<link name="([^"]+)">(?:(?!</link>).)*<inertial', re.S)
    had, has = holding.findall(text), holding.findall(patched)
    assert had == has and {"panda_leftfinger", "panda_rightfinger"} <= set(has)
    for finger in ("panda_leftfinger", "panda_rightfinger"):
        assert _link_inertial(patched, finger) == _link_inertial(text, finger)
    changed = [name for name in has if _link_inertial(patched, name) != _link_inertial(text, name)]
    assert changed == [f"panda_link{k}" for k in range(1, 8)]  # hand and link8 untouched


def test_template_export_opens_with_what_dynid_wrote(tmp_path):
    """A template export opens with dynid's comment after the XML declaration, as the chain
    export does (before: none, though the README says exported URDFs open with one): the
    template's name, the chain's links whose inertials were written, the joints' friction
    kept or written, what URDF leaves out; Pinocchio reads the file (a valid comment)."""
    pin = pytest.importorskip("pinocchio")
    path, chain = _template_chain()
    new = _identified(chain, seed=1)
    out = save_urdf(tmp_path / "p.urdf", new, template=path, base="panda_link0", tip="panda_hand")
    decl, header = out.read_text().split("\n")[:2]
    assert decl.startswith("<?xml")
    assert header.startswith("<!-- written by dynid ") and header.endswith(" -->")
    for said in (
        "into the template panda.urdf",
        "the <inertial> of the chain's 7 moving links (panda_link1 to panda_link7)",
        "the joints' <dynamics> as the template has them",
        "rotor inertia and friction offsets are not part of URDF",
    ):
        assert said in header, header
    fr = (np.full(7, 0.5), np.full(7, 0.25))
    out = save_urdf(
        tmp_path / "f.urdf",
        new,
        template=path,
        base="panda_link0",
        tip="panda_hand",
        dynamics=fr,
        template_dynamics=True,
    )
    header = out.read_text().split("\n")[1]
    assert "the joints' friction as <dynamics damping friction> (identified)" in header
    model = pin.buildModelFromUrdf(str(out))
    np.testing.assert_allclose(model.damping[:7], 0.5, rtol=0, atol=0)


def _link_inertial(text, name):
    """The <inertial> element of one link, as written."""
    block = re.search(rf'<link name="{name}">.*?</link>', text, re.S).group(0)
    return _INERTIAL.search(block).group(0)


def test_patched_template_gives_pinocchio_the_chain_exports_dynamics(tmp_path):
    """Pinocchio on the patched template, fingers locked, gives the chain export's M and g,
    and the file's total mass is the identified robot's: the identified link 7 holds the
    fingers, which the export no longer adds a second time (0.03 kg counted twice before)."""
    path, chain = _template_chain()
    new = _identified(chain, seed=2)
    patched = save_urdf(
        tmp_path / "p.urdf", new, template=path, base="panda_link0", tip="panda_hand"
    )
    q, _, _ = random_states(chain, 50, seed=4)
    M_p, g_p = _pin_M_g(patched, q, lock=_FINGERS)
    M_new, g_new = _pin_M_g(save_urdf(tmp_path / "new.urdf", new), q)
    np.testing.assert_allclose(M_p, M_new, atol=1e-10)
    np.testing.assert_allclose(g_p, g_new, atol=1e-10)
    np.testing.assert_allclose(M_new, dynid.mass_matrix(new, q), atol=1e-10)
    pin = pytest.importorskip("pinocchio")
    model = pin.buildModelFromUrdf(str(patched))
    np.testing.assert_allclose(
        sum(model.inertias[j].mass for j in range(1, model.njoints)), new.phi[:, 0].sum(), 1e-12
    )


def test_patched_template_without_other_branches_equals_chain_export(tmp_path):
    """A template whose only branch is the chain: Pinocchio's M and g equal the chain export's."""
    path = robot_data_urdf("ur_description/urdf/ur5_robot.urdf")
    chain = dynid.Robot.from_urdf(path, "base_link", "tool0")
    new = _identified(chain, seed=3)
    patched = save_urdf(tmp_path / "p.urdf", new, template=path, base="base_link", tip="tool0")
    exported = save_urdf(tmp_path / "c.urdf", new)
    q, _, _ = random_states(chain, 30, seed=5)
    M_p, g_p = _pin_M_g(patched, q)
    M_c, g_c = _pin_M_g(exported, q)
    np.testing.assert_allclose(M_p, M_c, atol=1e-10)
    np.testing.assert_allclose(g_p, g_c, atol=1e-10)
    np.testing.assert_allclose(g_c, dynid.gravity_torques(new, q), atol=1e-10)


def test_merged_move_puts_the_body_on_the_moving_link():
    """merged='move': the hand loses its inertial, link7 carries the whole body but the
    fingers (which keep their 0.015 kg each), phi reads back."""
    path, chain = _template_chain()
    new = _identified(chain, seed=6)
    text = patch_urdf_inertials(
        open(path).read(), new, base="panda_link0", tip="panda_hand", merged="move"
    )
    hand = re.search(r'<link name="panda_hand">.*?</link>', text, re.S).group(0)
    assert "<inertial" not in hand and "<visual" in hand
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        back = robot_from_urdf_string(text, "panda_link0", "panda_hand")
    np.testing.assert_allclose(back.phi, new.phi, rtol=1e-12, atol=1e-15)
    m7 = re.search(r'<link name="panda_link7">.*?<mass value="([^"]+)"', text, re.S).group(1)
    np.testing.assert_allclose(float(m7), new.phi[6, 0] - 0.03, rtol=1e-14)  # fingers kept


def test_subtract_refuses_a_rest_that_is_not_a_body(tmp_path, capsys):
    """The published link 7 (0.74 kg, identified without the hand) minus the template's
    0.73 kg hand is not a rigid body: an error naming the link, the hand and both remedies,
    through the library and the CLI (exit 2, no file written); --merged move writes it
    (issue 20: a 0.049 kg link with negative principal moments was written, exit 0)."""
    path, _ = _template_chain()
    text = open(path).read()
    with pytest.raises(ModelError) as info:
        patch_urdf_inertials(text, dynid.panda(), base="panda_link0", tip="panda_hand")
    msg = str(info.value)
    assert "link 'panda_link7'" in msg and "panda_hand" in msg, msg
    assert all(f"--merged {p}" in msg for p in ("subtract", "keep", "move")), msg
    # each remedy with the recording it fits (before: keep "if the identified data did not
    # include those bodies", move without a condition, for an arm recorded with its hand)
    assert (
        "recorded with them on it (the identified body holds them), export with --merged move"
        in msg
    )
    assert "recorded without them, with --merged keep" in msg
    fixed = re.search(r"links merged into it (\[.*?\])", msg).group(1)
    hand = sum(  # masses of the fixed links named, read from the template's text
        float(re.search(rf'<link name="{name}">.*?<mass value="([^"]+)"', text, re.S).group(1))
        for name in re.findall(r"'([^']+)'", fixed)
    )
    assert f"mass {dynid.panda().phi[6, 0] - hand:.6g} kg" in msg, msg
    assert f"the identified body is {dynid.panda().phi[6, 0]:.6g} kg, they are {hand:.6g} kg" in msg
    out = tmp_path / "p.urdf"
    argv = ["export", "--params", "panda", "--out", str(out), "--urdf-template", path]
    assert main(argv + ["--base", "panda_link0", "--tip", "panda_hand"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "link 'panda_link7'" in err[0] and "--merged keep" in err[0]
    assert not out.exists() and list(tmp_path.iterdir()) == []
    argv += ["--base", "panda_link0", "--tip", "panda_hand", "--merged", "move"]
    assert main(argv) == 0 and out.exists()


def test_names_with_xml_references_are_patched():
    """Link names written with character references and predefined entities (a&amp;b,
    &#99;) are the names the XML parser reads (issue 20: KeyError 'a&b')."""
    text = """<robot name="r">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a&amp;b"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="a&amp;b"><inertial><mass value="1"/><inertia ixx="0.1" iyy="0.1" izz="0.1"/>
  </inertial></link>
  <joint name="j2" type="revolute"><parent link="a&#38;b"/><child link="&#99;&lt;d&quot;"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/><limit lower="-1" upper="1" effort="1"
    velocity="1"/></joint>
  <link name='&#x63;&lt;d&quot;'/>
</robot>
"""
    chain = robot_from_urdf_string(text)
    assert chain.link_names == ("base", "a&b", 'c<d"')
    new = chain.with_inertials(
        [1.5, 2.0], [[0.1, 0, 0], [0, 0.2, 0]], np.tile([0.1, 0, 0, 0.2, 0, 0.3], (2, 1))
    )
    out = patch_urdf_inertials(text, new)
    np.testing.assert_allclose(robot_from_urdf_string(out).phi, new.phi, rtol=1e-15, atol=1e-17)
    assert '<link name="a&amp;b">' in out and "<link name='&#x63;&lt;d&quot;'>" in out


def test_template_with_another_chain_is_refused():
    """The UR5 template cannot carry the Panda's inertials."""
    text = open(robot_data_urdf("ur_description/urdf/ur5_robot.urdf")).read()
    with pytest.raises(ModelError, match="moving joints"):
        patch_urdf_inertials(text, dynid.panda(), base="base_link", tip="tool0")
    two = dynid.Robot.from_mdh([0, 1.0], [0, 0], [0, 0])
    other = dynid.Robot.from_mdh([0, 2.0], [0, 0], [0, 0])
    with pytest.raises(ModelError, match="another frame"):
        patch_urdf_inertials(urdf_from_robot(two), other)
    with pytest.raises(ModelError, match="merged must be one of"):
        patch_urdf_inertials(urdf_from_robot(two), two, merged="drop")


def test_links_without_inertial_get_one():
    """A self-closing link and a link without <inertial> receive the robot's inertial."""
    text = """<robot name="r">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <link name="a"/>
  <joint name="j2" type="continuous"><parent link="a"/><child link="b"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/></joint>
  <link name="b"><!-- <inertial> in a comment --><visual/></link>
</robot>
"""
    chain = robot_from_urdf_string(text)
    new = chain.with_inertials(
        [1.0, 2.0], [[0.1, 0, 0], [0, 0.2, 0]], np.tile([0.1, 0, 0, 0.2, 0, 0.3], (2, 1))
    )
    out = patch_urdf_inertials(text, new)
    back = robot_from_urdf_string(out)
    np.testing.assert_allclose(back.phi, new.phi, rtol=1e-15, atol=1e-17)
    assert "<!-- <inertial> in a comment -->" in out and '<link name="base"/>' in out


def test_chain_export_keeps_the_source_tip_name():
    """A Panda read to panda_link8 is exported with panda_link8 as its tip, not 'flange'."""
    path = pinocchio_panda_urdf()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        chain = dynid.Robot.from_urdf(path, "panda_link0", "panda_link8")
    text = urdf_from_robot(chain)
    assert '<link name="panda_link8"/>' in text and "flange" not in text
    moving = re.findall(r'<joint name="(panda_joint\d)" type="revolute"', text)
    assert moving == list(chain.joint_names)
    # the tip's fixed joint keeps the source's name (it was panda_link8_joint)
    assert re.findall(r'<joint name="([^"]+)" type="fixed"', text) == ["panda_joint8"]
    assert '<link name="flange"/>' in urdf_from_robot(dynid.panda())
    tooled = dynid.panda().with_tool(np.eye(4), 0.5, (0, 0, 0.05), name="gripper")
    assert '<link name="flange"/>' in urdf_from_robot(tooled)  # a later frame is not the tip


def test_cli_export_urdf_template_and_mjcf(tmp_path, capsys):
    """dynid export writes a patched URDF and an MJCF; a bad chain exits 2 with one line."""
    pytest.importorskip("mujoco")
    path, chain = _template_chain()
    params = tmp_path / "robot.toml"
    save_robot(params, _identified(chain, seed=8))
    out = tmp_path / "patched.urdf"
    argv = ["export", "--params", str(params), "--out", str(out), "--urdf-template", path]
    assert main(argv + ["--base", "panda_link0", "--tip", "panda_hand"]) == 0
    assert out.read_text().count("<mesh") == open(path).read().count("<mesh")
    assert main(["export", "--params", "panda", "--out", str(tmp_path / "p.xml")]) == 0
    assert "frictionloss" in capsys.readouterr().out
    assert main(argv + ["--tip", "panda_link3"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("dynid export: error:") and "\n" not in err


def test_merged_keep_exports_a_panda_identified_without_its_hand(tmp_path):
    """--merged keep: the published Panda (identified without its hand) goes into the
    vendor's URDF with the hand kept byte for byte; Pinocchio on the file gives the
    published arm's M and g plus the hand's, computed from the template's own hand."""
    path, chain = _template_chain()
    text = open(path).read()
    out = tmp_path / "p.urdf"
    argv = ["export", "--params", "panda", "--out", str(out), "--urdf-template", path]
    assert main([*argv, "--base", "panda_link0", "--tip", "panda_hand", "--merged", "keep"]) == 0
    patched = out.read_text()
    hand = r'<link name="panda_hand">.*?</link>'
    assert re.search(hand, patched, re.S).group(0) == re.search(hand, text, re.S).group(0)
    m7 = re.search(r'<link name="panda_link7">.*?<mass value="([^"]+)"', patched, re.S).group(1)
    np.testing.assert_allclose(float(m7), dynid.panda().phi[6, 0], rtol=1e-15)
    # Pinocchio on the files: from the template to the patch, M and g change exactly as
    # between chain exports of the template's own links 1..7 and the published arm
    own = chain.phi.copy()
    own[6] = _own_link_phi(text, "panda_link7")
    q, _, _ = random_states(chain, 30, seed=8)
    M_t, g_t = _pin_M_g(path, q, lock=_FINGERS)
    M_p, g_p = _pin_M_g(out, q, lock=_FINGERS)
    M_new, g_new = _pin_M_g(save_urdf(tmp_path / "new.urdf", dynid.panda()), q)
    M_old, g_old = _pin_M_g(save_urdf(tmp_path / "old.urdf", chain.with_params(own)), q)
    np.testing.assert_allclose(M_p - M_t, M_new - M_old, atol=1e-10)
    np.testing.assert_allclose(g_p - g_t, g_new - g_old, atol=1e-10)


def _own_link_phi(text, name):
    """phi (10,) of one link's own <inertial> in the template (no rotation in these files)."""
    block = re.search(rf'<link name="{name}">.*?</link>', text, re.S).group(0)
    m = float(re.search(r'<mass value="([^"]+)"', block).group(1))
    c = np.array(
        [float(x) for x in re.search(r'<origin[^>]*xyz="([^"]+)"', block).group(1).split()]
    )
    rpy = re.search(r'<origin[^>]*rpy="([^"]+)"', block)
    assert rpy is None or not any(float(x) for x in rpy.group(1).split())
    attrs = {
        a: float(re.search(rf'{a}="([^"]+)"', block).group(1))
        for a in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
    }
    I = np.array(
        [
            [attrs["ixx"], attrs["ixy"], attrs["ixz"]],
            [attrs["ixy"], attrs["iyy"], attrs["iyz"]],
            [attrs["ixz"], attrs["iyz"], attrs["izz"]],
        ]
    )
    J = I + m * (c @ c * np.eye(3) - np.outer(c, c))  # about the link origin (Steiner)
    mc = m * c
    return np.array([m, *mc, J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2]])


def test_a_template_fixed_link_of_negative_mass_is_refused(tmp_path, capsys):
    """A hand of negative mass in the template is refused in one line naming it, under
    every --merged policy (issue 28: it was written silently)."""
    path, chain = _template_chain()
    text = open(path).read()
    bad = re.sub(
        r'(<link name="panda_hand">.*?<mass value=")([^"]+)(")',
        r"\g<1>-0.73\g<3>",
        text,
        count=1,
        flags=re.S,
    )
    template = tmp_path / "bad.urdf"
    template.write_text(bad)
    for policy in ("subtract", "move", "keep"):
        with pytest.raises(ModelError, match=r"link 'panda_hand' has a negative mass \(-0.73 kg\)"):
            patch_urdf_inertials(
                bad,
                _identified(chain, seed=9),
                base="panda_link0",
                tip="panda_hand",
                merged=policy,
            )
    out = tmp_path / "p.urdf"
    argv = ["export", "--params", "panda", "--out", str(out), "--urdf-template", str(template)]
    assert main([*argv, "--base", "panda_link0", "--tip", "panda_hand", "--merged", "keep"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "negative mass" in err[0] and not out.exists()


def _truth_with_fingers(seed):
    """Pinocchio's Panda with its fingers locked at 0 (merged into joint 7's body by
    Pinocchio), each body scaled by a factor in [1.05, 1.3]: the arm the logs were recorded
    on, and dynid's chain of the template holding the same bodies (link frames = joint frames)."""
    pin = pytest.importorskip("pinocchio")
    path, chain = _template_chain()
    full = pin.buildModelFromUrdf(path)
    truth = pin.buildReducedModel(full, [full.getJointId(n) for n in _FINGERS], pin.neutral(full))
    truth.gravity.linear = np.array([0.0, 0.0, -9.80665])
    rng = np.random.default_rng(seed)
    phi = np.zeros((7, 10))
    for j in range(1, 8):
        old, s = truth.inertias[j], rng.uniform(1.05, 1.3)
        truth.inertias[j] = pin.Inertia(s * old.mass, old.lever, s * old.inertia)
        m, c, Ic = truth.inertias[j].mass, truth.inertias[j].lever, truth.inertias[j].inertia
        J = Ic + m * (c @ c * np.eye(3) - np.outer(c, c))
        phi[j - 1] = [m, *(m * c), J[0, 0], J[0, 1], J[0, 2], J[1, 1], J[1, 2], J[2, 2]]
    return path, truth, chain.with_params(phi)


@pytest.mark.parametrize("merged", ["subtract", "move"])
def test_template_export_counts_fingers_once(tmp_path, caplog, merged):
    """An arm recorded with its hand and fingers: Pinocchio's RNEA of the patched template
    (fingers locked) equals the truth's to 1e-10 and the file's total mass is the truth's;
    the fingers keep the template's inertials and link 7 is written without them, and a
    note says so (before: the template's 0.03 kg of fingers were added again, a Panda
    trial 0.515 % off its truth instead of 0.031 %; then the fingers lost their inertials,
    which a simulator needs for a moving link)."""
    pin = pytest.importorskip("pinocchio")
    path, truth, identified = _truth_with_fingers(seed=11)
    out = tmp_path / "p.urdf"
    with caplog.at_level(dynid.progress.NOTE):
        patch = patch_urdf_inertials(
            open(path).read(), identified, base="panda_link0", tip="panda_hand", merged=merged
        )
    notes = [r.getMessage() for r in caplog.records if r.levelno == dynid.progress.NOTE]
    out.write_text(patch)
    assert any("panda_leftfinger (0.015 kg" in n and "--merged keep" in n for n in notes), notes
    text = open(path).read()
    for finger in ("panda_leftfinger", "panda_rightfinger"):
        assert _link_inertial(patch, finger) == _link_inertial(text, finger)
    full = pin.buildModelFromUrdf(str(out))
    total = sum(full.inertias[j].mass for j in range(1, full.njoints))
    np.testing.assert_allclose(total, sum(truth.inertias[j].mass for j in range(1, 8)), 1e-12)
    model = pin.buildReducedModel(full, [full.getJointId(n) for n in _FINGERS], pin.neutral(full))
    model.gravity.linear = truth.gravity.linear
    q, dq, ddq = random_states(identified, 20, seed=12)
    d_file, d_truth = model.createData(), truth.createData()
    for i in range(len(q)):
        np.testing.assert_allclose(
            pin.rnea(model, d_file, q[i], dq[i], ddq[i]),
            pin.rnea(truth, d_truth, q[i], dq[i], ddq[i]),
            atol=1e-10,
        )


def test_merged_keep_leaves_the_fingers(tmp_path):
    """--merged keep (a body identified without the hand): the fingers' inertials stay."""
    path, chain = _template_chain()
    text = open(path).read()
    patch = patch_urdf_inertials(text, chain, base="panda_link0", tip="panda_hand", merged="keep")
    for finger in ("panda_leftfinger", "panda_rightfinger"):
        assert _link_inertial(patch, finger) == _link_inertial(text, finger)


def test_a_branch_off_an_earlier_body_keeps_its_inertial():
    """Only links past the tip are the identified last body's: a slider on link a (moving
    on its own while the chain is recorded) keeps its inertial and is no part of the
    identified bodies; the finger on link b keeps its own too, but is lumped into the
    identified b: Pinocchio's total mass is the identified one plus the slider's."""
    pin = pytest.importorskip("pinocchio")
    inertial = '<inertial><mass value="{m}"/><inertia ixx="0.01" iyy="0.01" izz="0.01"/></inertial>'
    slider = '<limit lower="0" upper="0.1" effort="1" velocity="1"/>'
    hinge = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    text = f"""<robot name="r">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/>{hinge}</joint>
  <link name="a">{inertial.format(m=2.0)}</link>
  <joint name="s" type="prismatic"><parent link="a"/><child link="slide"/>
    <origin xyz="0 0.2 0"/><axis xyz="1 0 0"/>{slider}</joint>
  <link name="slide">{inertial.format(m=0.5)}</link>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/>{hinge}</joint>
  <link name="b">{inertial.format(m=1.0)}</link>
  <joint name="f" type="prismatic"><parent link="b"/><child link="finger"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>{slider}</joint>
  <link name="finger">{inertial.format(m=0.1)}</link>
</robot>
"""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        chain = robot_from_urdf_string(text, "base", "b")
    new = chain.with_params(chain.phi * np.array([[1.2], [1.3]]))
    out = patch_urdf_inertials(text, new, base="base", tip="b")
    assert '<link name="slide"><inertial>' in out and '<link name="finger"><inertial>' in out
    model = pin.buildModelFromXML(out)
    total = sum(model.inertias[j].mass for j in range(1, model.njoints))
    np.testing.assert_allclose(total, new.phi[:, 0].sum() + 0.5, rtol=1e-12)


def _arm_with_finger(finger_inertia):
    """Two links a, b and a prismatic finger (0.1 kg) past the tip b."""
    inertial = '<inertial><mass value="{m}"/><inertia ixx="{i}" iyy="{i}" izz="{i}"/></inertial>'
    hinge = '<limit lower="-1" upper="1" effort="1" velocity="1"/>'
    return f"""<robot name="r">
  <link name="base"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="a"/>
    <axis xyz="0 0 1"/>{hinge}</joint>
  <link name="a">{inertial.format(m=2.0, i=0.01)}</link>
  <joint name="j2" type="revolute"><parent link="a"/><child link="b"/>
    <origin xyz="0.5 0 0"/><axis xyz="0 1 0"/>{hinge}</joint>
  <link name="b">{inertial.format(m=1.0, i=0.01)}</link>
  <joint name="f" type="prismatic"><parent link="b"/><child link="finger"/>
    <origin xyz="0.3 0 0"/><axis xyz="0 1 0"/>{hinge}</joint>
  <link name="finger">{inertial.format(m=0.1, i=finger_inertia)}</link>
</robot>
"""


def test_fingers_heavier_than_the_identified_body_lose_their_inertials_with_a_warning():
    """A template whose finger alone has more inertia (0.05 kg m^2) than the identified
    last body holds (0.03 kg m^2 about each axis; a Baxter trial's fingers: 0.01 kg m^2
    each against J7zz 0.039): the body cannot be split into the finger and a rest, so the
    whole body goes on the moving link and the finger's inertial goes, in a warning that
    names it, instead of an error; Pinocchio with the finger locked reads back the
    identified bodies."""
    pin = pytest.importorskip("pinocchio")
    text = _arm_with_finger(0.05)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DynidWarning)
        chain = robot_from_urdf_string(text, "base", "b")
    # b: 1.1 kg, its rotational inertia about the CoM 0.03 kg m^2 about each axis
    c = chain.phi[1, 1:4] / chain.phi[1, 0]
    new = chain.with_inertials(
        chain.phi[:, 0], [chain.com[0], c], [chain.inertia[0], 0.03 * np.eye(3)]
    )
    for merged in ("subtract", "move"):
        with pytest.warns(DynidWarning, match="written without their inertials") as caught:
            out = patch_urdf_inertials(text, new, base="base", tip="b", merged=merged)
        assert any("finger (0.1 kg" in str(w.message) for w in caught)
        assert '<link name="finger"></link>' in out
        model = pin.buildModelFromXML(out)
        model = pin.buildReducedModel(model, [model.getJointId("f")], pin.neutral(model))
        for j, phi in zip((1, 2), new.phi, strict=True):
            Y = model.inertias[j]
            np.testing.assert_allclose([Y.mass, *(Y.mass * Y.lever)], phi[:4], atol=1e-12)
    out = patch_urdf_inertials(_arm_with_finger(0.001), new, base="base", tip="b")
    assert "finger" in out and '<link name="finger"><inertial>' in out
