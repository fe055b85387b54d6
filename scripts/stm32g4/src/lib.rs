// Never built: the crate exists so that cargo fetches stm32g4 (see Cargo.toml).
