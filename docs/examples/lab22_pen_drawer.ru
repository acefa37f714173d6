# The twenty-second round's lab: a pen drawer, a new region added by a SPARQL update (no Turtle file): an
# open box on the kitchen table east of the pen, its inside from its floor (0.76 m, 1 cm above the table's top) to its rim
# (0.80 m). The class is the lab's, under home:ObjectPlace, in the ontology graph. In a store of its own:
#   cbrs --store S init
#   cbrs --store S update --file docs/examples/lab22_pen_drawer.ru
#   cbrs --store S load --graph requirements docs/examples/lab22_pen_into_the_drawer.ttl
#   cbrs --store S run PenIntoTheDrawer --seed 0 --json
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX lab22: <https://example.org/lab22#>
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
