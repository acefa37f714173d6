# LOAD of a local file: reading /etc/passwd into the store, unless federation_allow says otherwise.
LOAD <file:///etc/passwd> INTO GRAPH <urn:stolen>
