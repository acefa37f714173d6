INSERT DATA { GRAPH <urn:bad:g> { <urn:bad:s> <urn:bad:p> "o" }
