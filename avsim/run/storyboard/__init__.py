"""OpenSCENARIO's storyboard at run time: conditions judged on the truth, the storyboard
elements' states, and the director that starts the actions on the world's actors."""
