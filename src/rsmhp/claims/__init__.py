"""Claims of each study: key numbers and verdict rules evaluated on the study's statistics."""
