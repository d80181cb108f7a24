"""Workflow support: config and schema checks, intermediate-file contracts, atomic I/O, code
digests, parallel fan-out, resources, cluster pre-flight, the comparison protocol and the
glue of rule scripts (``script``)."""
