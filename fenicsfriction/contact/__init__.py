"""Two-body frictional contact: node-to-segment contact between two bodies in one mesh."""
