"""The report: claims ledger, verdict rules, the paper's statements, rendering, Markdown,
palette, figures' theme, provenance, verify and the portability drill."""
