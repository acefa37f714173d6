"""Small named taxonomies with known answers, shared by the reasoner tests."""

from __future__ import annotations

from cbrs.reasoner.taxonomy import ROOT, Link, TaxonomyIndex

E = "http://example.org/t#"


def isa(child: str, parent: str) -> Link:
    return Link(E + child if child != "Thing" else ROOT, E + parent if parent != "Thing" else ROOT, "is-a")


def part(part_: str, whole: str) -> Link:
    return Link(E + part_, E + whole, "has-part")


def figure5() -> TaxonomyIndex:
    """Our reading of the paper's Figure 5 (the figure itself is not in the text): A is the root
    (owl:Thing); B below it; C and E siblings under F at depth 2; D at depth 2 in another branch.
    Then Sim(eC, eE) = 2*2/(1+1+2*2) = 0.67 (Situation 2), Sim(eB, eA) = 1/(1+1) instead of
    Wu-Palmer's 0 (Situation 1), and Sim(eE, eD) = 1/(1+3+2), small, through the root."""
    return TaxonomyIndex.from_links(
        [isa("B", "Thing"), isa("F", "B"), isa("C", "F"), isa("E", "F"), isa("G", "Thing"), isa("D", "G")]
    )


def positions() -> TaxonomyIndex:
    """Position and Location: siblings under SpatialData, both with x and y parts."""
    return TaxonomyIndex.from_links(
        [
            isa("Information", "Thing"),
            isa("SpatialData", "Information"),
            isa("Position", "SpatialData"),
            isa("Location", "SpatialData"),
            isa("RobotPosition", "Position"),
            isa("PersonPosition", "Position"),
            isa("RobotLocation", "Location"),
            isa("Coordinate", "Information"),
            isa("XCoordinate", "Coordinate"),
            isa("YCoordinate", "Coordinate"),
            part("XCoordinate", "Position"),
            part("YCoordinate", "Position"),
            part("XCoordinate", "Location"),
            part("YCoordinate", "Location"),
            isa("Colour", "Thing"),
            isa("MarkerColour", "Colour"),
            isa("ColourOfMarker", "MarkerColour"),
        ]
    )
