"""The HTTP side of cbrs serve: the SPARQL 1.1 Protocol endpoint (and, later, the knowledge browser)."""
