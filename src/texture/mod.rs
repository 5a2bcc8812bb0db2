//! Classic procedural solid textures (marble, ring wood, stone, clouds) behind one small trait.
