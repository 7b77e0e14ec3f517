"""Robot files, one module per format, each reading and writing its format side by side.

* :mod:`~dynid.io.robot.urdf`: URDF (``load_urdf``: a serial chain, fixed joints merged;
  ``save_urdf``: a chain, or a template URDF with its inertials patched,
  :mod:`~dynid.io.robot.urdf_patch`; the reading is in :mod:`~dynid.io.robot.urdf_parse`);
* :mod:`~dynid.io.robot.toml`: dynid's own TOML description (``load_toml``, ``save_toml``);
* :mod:`~dynid.io.robot.mjcf`: MJCF, MuJoCo's format (``save_mjcf``; no reader).

The model layer knows no file format: :meth:`dynid.Robot.from_urdf` and
:meth:`dynid.Robot.from_toml` are facades that import their reader from here when called.
"""
