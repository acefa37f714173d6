# Take the right arm off the dual-arm robot, leaving a robot with one arm, the left, on the torso (the
# other variant of lab6_one_arm.ru): the arm, the robot's home:hasArm of it, its gripper and everything
# said of the two, in one update. The arm bands stay: the left hand names the same ones. The left arm
# keeps home:armSide "left": it folds to its left, as it did beside the right arm.
#   cbrs update --file docs/examples/lab6_one_arm_left.ru
#   cbrs run RobotArmServeACup --seed 0 --json     (the left arm reaches the cup and the tap: it takes the
#                                                   cup below the tap, sets it down and pushes the lever)
#   cbrs run FetchMyPen --seed 0 --json            (refused before anything moves: the left arm does not
#                                                   reach the pen)
PREFIX home:  <https://w3id.org/cbrs/home#>
PREFIX world: <https://w3id.org/cbrs/world#>
DELETE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    ?robot home:hasArm world:CytonDualArm01RightArm .
    world:CytonDualArm01RightArm ?p ?o .
    ?hand ?hp ?ho .
  }
}
WHERE {
  GRAPH <https://w3id.org/cbrs/graph/map> {
    ?robot home:hasArm world:CytonDualArm01RightArm .
    world:CytonDualArm01RightArm ?p ?o .
    OPTIONAL {
      world:CytonDualArm01RightArm home:hasGripper ?hand .
      ?hand ?hp ?ho .
    }
  }
}
