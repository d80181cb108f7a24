"""Report sections of each study: prose, tables and appendix in Markdown, from its claims."""
