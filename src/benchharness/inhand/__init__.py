"""In-hand manipulation benchmark: file formats and the published-data import.

* :mod:`.records` -- the typed, columnar form of a recorded-results file;
* :mod:`.fileformat` -- reading/writing task and results files (CSV, JSON);
* :mod:`.ods` -- a small OpenDocument spreadsheet reader (odfpy);
* :mod:`.bih_import` -- conversion of the published dataset into ``tasks/inhand``.

Metric computation lives in :mod:`benchharness.metrics`; nothing here imports
a simulator.
"""
