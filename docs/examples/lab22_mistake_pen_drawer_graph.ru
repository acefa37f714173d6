# A newcomer's mistake of the twenty-second round: lab22_pen_drawer.ru with its own PREFIX graph:, written
# <https://w3id.org/cbrs/graph#> (a hash) where the store's graphs are <https://w3id.org/cbrs/graph/map> and so
# on (a slash; cbrs update binds graph: itself). The drawer went into two graphs no task reads. In a store of
# its own:
#   cbrs --store S init
#   cbrs --store S update --file docs/examples/lab22_mistake_pen_drawer_graph.ru
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX lab22: <https://example.org/lab22#>
PREFIX graph: <https://w3id.org/cbrs/graph#>
PREFIX owl:   <http://www.w3.org/2002/07/owl#>
PREFIX rdfs:  <http://www.w3.org/2000/01/rdf-schema#>
INSERT DATA {
  GRAPH graph:ontology {
    lab22:PenDrawer a owl:Class ; rdfs:subClassOf home:ObjectPlace ; rdfs:label "pen drawer"@en .
  }
  GRAPH graph:map {
    lab22:PenDrawer1 a lab22:PenDrawer , owl:NamedIndividual ; rdfs:label "the pen drawer"@en ;
      home:minX 8.17 ; home:maxX 8.42 ; home:minY 3.05 ; home:maxY 3.30 ; home:minZ 0.76 ; home:maxZ 0.80 .
  }
}
