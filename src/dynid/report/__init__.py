"""The HTML report of a run: ``report.html``, one self-contained page that answers the
command's question first (a verdict, the figures, the tables with named columns and units),
then shows the run's inputs, every file's results, the printed summary and the messages.

* :mod:`.page`: the page (:func:`render_html_report`, :func:`save_html_report`);
* :mod:`.answers`: which answer each command opens with; one module per answer
  (:mod:`.identify`, :mod:`.torques`, :mod:`.feasible`, :mod:`.observe`, :mod:`.demo`);
* :mod:`.json_tables`: any JSON result as tables; :mod:`.html`: the HTML pieces.
"""

from .page import input_files, render_html_report, save_html_report
from .run import REPORT_NAME, Answer, ReportTable, RunFiles, RunSummary

__all__ = [
    "REPORT_NAME",
    "Answer",
    "ReportTable",
    "RunFiles",
    "RunSummary",
    "input_files",
    "render_html_report",
    "save_html_report",
]
