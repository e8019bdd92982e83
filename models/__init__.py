"""The joint's MJCF (``joint.xml``), shipped as package data: load it with
``importlib.resources.files("models") / "joint.xml"`` (see ``twin.physics.model``)."""
