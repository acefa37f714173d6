# A service description whose parts are blank nodes: nothing could read, address or delete them.
PREFIX cbrs: <https://w3id.org/cbrs/core#>
INSERT DATA { GRAPH <https://w3id.org/cbrs/graph/services> {
  <urn:evil:camera> a cbrs:DynamicPerceptionComponent ;
    cbrs:hasOWLSModel [ a cbrs:OWLSModel ; cbrs:hasOutput [ a cbrs:Parameter ] ] .
} }
