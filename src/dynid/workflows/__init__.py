"""Workflows on files: the entry points the commands call, with every check and policy a
command applies, so that the Python API and the ``dynid`` commands behave the same.

Each takes one frozen options class (typed values, never flag strings), validated in
``__post_init__`` (:mod:`~dynid.workflows.options`), and returns a frozen result; an
:class:`~dynid.exceptions.OptionError` carries the field at fault, which the command line
names by its flag.

* :mod:`~dynid.workflows.data_files`: the kind of a data file; torque logs and static
  data read strictly and checked against the robot (joint count, recorded robot, log
  cleaning); the column map a model's data were read with.
* :mod:`~dynid.workflows.prior`: the prior of a consistent fit (``--prior``), checked.
* :mod:`~dynid.workflows.identify`: identification from a data file (both routes, and
  the one-step consistent fit).
* :mod:`~dynid.workflows.retrieve`: feasible parameters from a model or static data file.
* :mod:`~dynid.workflows.friction`: friction fitted to a model's torque residual on one
  or more log files (the law chosen on held-out blocks, or the one asked for).
* :mod:`~dynid.workflows.validate`: a model validated against one or more log files
  (typed options in, errors pooled and per recording out).
* :mod:`~dynid.workflows.payload`: a load identified on a known arm from static data or
  one or more torque logs.
* :mod:`~dynid.workflows.recordings`: several torque recordings read for a model, each
  problem one line naming the file.
* :mod:`~dynid.workflows.simulate`: a simulated torque log (the trajectory scaled into
  the limits, the friction, the effects outside the model, contacts).
* :mod:`~dynid.workflows.export`: a robot file exported (its chain, friction and drive).
* :mod:`~dynid.workflows.acquire_static`: static data from a simulated controller.
* :mod:`~dynid.workflows.excite`: an exciting trajectory designed and sampled.

The layer sits above :mod:`dynid.io` (it reads files) and below the command line, which
parses, calls one of these, prints and saves.
"""
