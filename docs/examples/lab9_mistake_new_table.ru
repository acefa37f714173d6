# A newcomer's mistake (the ninth round, docs/tasks.md "A ninth round"): the lab's new kitchen table put in
# place of the bundled one by one update, the old table's statements deleted and the new table inserted,
# but the things that stand on the table (the cup, the pen, the water dispenser) still naming the old one
# (home:isLocatedOn world:KitchenTable). Refused, the store as it was (docs/examples/lab9_new_kitchen_table.ru
# re-points them in the same update):
#   cbrs --store S update --file docs/examples/lab9_mistake_new_table.ru
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
PREFIX lab9:  <https://example.org/lab9#>
PREFIX rdfs:  <http://www.w3.org/2000/01/rdf-schema#>
DELETE WHERE { GRAPH <https://w3id.org/cbrs/graph/map> { world:KitchenTable ?p ?o } } ;
INSERT DATA {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    lab9:KitchenTable2 a home:Table ; rdfs:label "the lab's new kitchen table, 1.8 m long"@en ;
        home:isLocated world:Kitchen ;
        home:minX 7.0 ; home:maxX 8.8 ; home:minY 3.0 ; home:maxY 4.5 ; home:minZ 0.0 ; home:maxZ 0.75 ;
        home:dockingPose world:KitchenTableDock .
  }
}
