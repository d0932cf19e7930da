"""The running station assembled from a configuration: core, adapters, element loading, session state.
"""
