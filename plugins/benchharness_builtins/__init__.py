"""Built-in plugins of benchharness.

Each module here is named by an entry point in the ``benchharness`` group of
this distribution's ``pyproject.toml`` and is loaded exactly like a
third-party plugin: there is no other registry. They share one style:

* one ``@hookimpl`` function per kind, typed ``-> list[Registration]``,
  called by the manager through pluggy's hook relay;
* the items are listed explicitly from the data that defines them (the tier
  file, the task files, the robot configs, the strategy packages'
  ``REGISTRATIONS``, the backends' capability flags, the sensor configs),
  never by scanning modules for an attribute name;
* factories import heavy code (torch, engines, meshes) only when called, and
  metadata that needs more than a constant (a robot's DOF and groups) is a
  function the manager calls when the metadata is first read.
"""
