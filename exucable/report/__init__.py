"""Self-contained HTML reports (inline images, no network)."""

from .plan_html import plan_report_html

__all__ = ["plan_report_html"]
