# Take the left arm off the dual-arm robot, leaving a robot with one arm, the right, on the torso (a lab
# with one arm on a table): the arm, the robot's home:hasArm of it, its gripper and everything said of
# the two, in one update, so the map is never half without it. The arm bands stay: the right hand names
# the same ones (ontologies/world.ttl). The remaining arm keeps home:armSide "right": it folds to its
# right (docs/simulation.md, "A robot with one arm").
#   cbrs update --file docs/examples/lab6_one_arm.ru
#   cbrs home
#   cbrs run RobotArmServeACup --seed 0 --json     (refused before anything moves: the right arm does
#                                                   not reach the cup, and there is no arm to pass it)
#   cbrs run FetchMyPen --seed 0 --json            (the right arm reaches the pen and the platform)
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
DELETE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    ?robot home:hasArm world:CytonDualArm01LeftArm .
    world:CytonDualArm01LeftArm ?p ?o .
    ?hand ?hp ?ho .
  }
}
WHERE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    ?robot home:hasArm world:CytonDualArm01LeftArm .
    world:CytonDualArm01LeftArm ?p ?o .
    OPTIONAL {
      world:CytonDualArm01LeftArm home:hasGripper ?hand .
      ?hand ?hp ?ho .
    }
  }
}
