"""FMI 2.0 co-simulation: dcsim scenarios exported as FMUs, FMUs coupled with fmpy.

- :func:`dcsim.fmu.export.export_fmu` builds a closed-loop or plant-only FMU
  (``dcsim fmu export``); the slaves are in :mod:`dcsim.fmu.slaves`, their variables in
  :mod:`dcsim.fmu.variables`.
- :mod:`dcsim.fmu.cosim` couples a plant FMU and a controller FMU (``dcsim fmu cosim``).

See ``docs/fmu.md``.
"""
