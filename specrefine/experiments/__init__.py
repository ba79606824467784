"""The paper's experiments read from sweep tables: figures, the comparison and repair claims, failure reports."""
