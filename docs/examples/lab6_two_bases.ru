# A second mobile base in the home: a Pioneer like the bundled one, parked in the bedroom, with its own
# platform and colour marker (blue ahead, red behind), in one update. The simulation builds both; a run
# drives the base its plan works (the device of its drives, the marker colours its locator is given), and
# a plan that works two, or names none, is refused before anything moves (docs/simulation.md, "A home
# with no mobile base"). Its components are not advertised here: a lab registers them
# (docs/examples/lab6_second_base_components.ttl), and a run then composes once per base and drives one.
#   cbrs update --file docs/examples/lab6_two_bases.ru
#   cbrs home                                        (mobile robots: P3DX01, P3DX02; what that allows)
#   cbrs run RobotArmServeACup --seed 0 --json       (the arms: it runs)
#   cbrs run FetchMyPen --seed 0 --json              (P3DX01's components and marker: it drives P3DX01)
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX owl:   <http://www.w3.org/2002/07/owl#>
PREFIX rdfs:  <http://www.w3.org/2000/01/rdf-schema#>
PREFIX svc:   <https://w3id.org/cbrs/service#>
PREFIX world: <https://w3id.org/cbrs/world#>
INSERT DATA {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    svc:P3DX02 a home:CarrierRobot , owl:NamedIndividual ; rdfs:label "Pioneer 3-DX 2"@en ;
        home:hasPlatform world:P3DX02Platform ; home:hasMarker world:P3DX02Marker ;
        home:x 2.0 ; home:y 7.0 ; home:yaw 0.0 ; home:sizeX 0.45 ; home:sizeY 0.38 .
    world:P3DX02Platform a home:RobotPlatform , owl:NamedIndividual ; rdfs:label "carrying platform 2"@en ;
        home:maxZ 0.45 .
    world:P3DX02Marker a home:ColourMarker , owl:NamedIndividual ; rdfs:label "colour marker 2"@en ;
        home:hasColour world:P3DX02MarkerColours ;
        home:sizeX 0.12 ; home:sizeY 0.30 ; home:markerSeparation 0.33 .
    world:P3DX02MarkerColours a home:ColourOfMarker , owl:NamedIndividual ; rdfs:label "colours of marker 2"@en ;
        home:frontColourName "blue" ; home:rearColourName "red" .
  }
}
