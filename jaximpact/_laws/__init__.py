"""What a contact is: the force laws, their table of per-law facts, their dynamics and exact
solutions. The bottom layer: imports nothing of jaximpact but the leaf helpers."""
