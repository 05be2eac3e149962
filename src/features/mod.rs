//! HumanML3D 263-dim features: extraction from joint positions and `recover_from_ric`.
