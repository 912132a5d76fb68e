"""server/world"""
