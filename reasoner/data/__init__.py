"""Generated evaluation data: the paper testbed (see reasoner.testbed) and its ground truth."""
