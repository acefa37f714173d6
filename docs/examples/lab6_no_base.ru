# Take the mobile base out of the home, leaving a lab with only the table robot (its arms, no base): the
# Pioneer's pose and footprint, its platform, its colour marker and the marker's colours, everything
# graph:map says of them, in one update, so the map is never half without it. The Pioneer's components
# (NavigateToPlace_P3DX01, DeliverObject_P3DX01, ...) and those that work it from elsewhere (the ceiling
# cameras' LocateMobileRobot, the arms' HandOverOntoPlatform) stay advertised: the simulation has no
# implementation of them in a home with no base, and a run plans without them, saying why
# (docs/simulation.md, "A home with no mobile base"). A lab that never has a base may deregister the
# Pioneer's own (cbrs deregister svc:NavigateToPlace_P3DX01 ...): the refusals then say no component
# provides what the task needs.
#   cbrs update --file docs/examples/lab6_no_base.ru
#   cbrs home                                        (mobile robots: none, and what that allows)
#   cbrs run RobotArmServeACup --seed 0 --json       (the arms alone: it runs)
#   cbrs run FetchMyPen                              (refused before the world is built: no base)
#   cbrs run RobotSelfPosition                       (refused: no marker to find)
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX svc:   <https://w3id.org/cbrs/service#>
DELETE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    svc:P3DX01 ?p ?o .
    ?part ?pp ?po .
    ?colours ?cp ?co .
  }
}
WHERE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    svc:P3DX01 ?p ?o .
    OPTIONAL {
      svc:P3DX01 home:hasPlatform|home:hasMarker ?part .
      ?part ?pp ?po .
      OPTIONAL { ?part home:hasColour ?colours . ?colours ?cp ?co . }
    }
  }
}
