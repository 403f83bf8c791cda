"""Message schemas, wire codec and key expressions: the contract between services."""
