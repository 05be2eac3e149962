"""Caption set and paraphrase probes for measuring text encoders (see measure-text-encoder.py).

The captions follow `src/dataset/captions.rs` (Bandai labels: subject + verb phrase, with
style variants) plus the actions issue 28 adds from CMU and HDM05. Paraphrases avoid the
captions' verbs where English allows; each lists the classes that count as right.
"""

ACTIONS = {
    "walk": ["walks forward", "walks straight ahead", "is walking forward"],
    "run": ["runs forward", "jogs forward", "is running"],
    "dash": ["dashes forward", "sprints forward", "runs forward fast"],
    "walk-back": ["walks backwards", "steps backwards", "walks back"],
    "walk-left": ["walks to the left", "moves sideways to the left", "steps to the left"],
    "walk-right": ["walks to the right", "moves sideways to the right", "steps to the right"],
    "walk-turn-left": ["walks and turns left", "turns left while walking", "walks in a left turn"],
    "walk-turn-right": ["walks and turns right", "turns right while walking", "walks in a right turn"],
    "bow": ["bows", "takes a bow", "bends forward in a bow"],
    "bye": ["waves goodbye", "waves a hand to say bye", "says goodbye with a wave"],
    "byebye": ["waves goodbye with both hands", "waves both hands to say goodbye", "says bye bye"],
    "guide": ["guides someone with a hand", "points the way with a hand", "shows the way"],
    "respond": ["responds with a gesture", "answers with a nod and a gesture", "reacts to someone"],
    "call": ["calls someone over", "beckons someone to come", "calls out to someone"],
    "punch": ["punches", "throws a punch", "punches forward"],
    "kick": ["kicks", "kicks forward", "does a kick"],
    "slash": ["slashes with a sword", "swings a sword", "makes a slashing attack"],
    "dance": ["dances", "is dancing", "dances energetically"],
    "wave-both": ["waves both hands", "waves with both arms", "raises both hands and waves"],
    "wave-left": ["waves the left hand", "waves with the left arm", "raises the left hand and waves"],
    "wave-right": ["waves the right hand", "waves with the right arm", "raises the right hand and waves"],
    "raise-both": ["raises both hands", "lifts both arms above the head", "puts both hands up"],
    "raise-left": ["raises the left hand", "lifts the left arm above the head", "puts the left hand up"],
    "raise-right": ["raises the right hand", "lifts the right arm above the head", "puts the right hand up"],
    # CMU / HDM05 / DeepMimic classes (issue 28).
    "jump": ["jumps up and down", "jumps in place", "jumps forward"],
    "hop": ["hops on one leg", "hops forward", "hops on the spot"],
    "squat": ["squats down", "does a squat", "squats and stands back up"],
    "pick-up": ["picks something up from the floor", "puts something down on the floor", "bends down and picks up an object"],
    "lie-down": ["lies down on the floor", "lies down on the ground", "gets down and lies on the floor"],
    "sit": ["sits down", "sits on a chair", "sits down and stands up"],
    "get-up": ["gets up from the floor", "stands up from the ground", "rises from lying on the floor"],
    "climb": ["climbs up", "climbs a ladder", "climbs onto a box"],
    "crawl": ["crawls forward", "crawls on hands and knees", "crawls on the floor"],
    "throw": ["throws a ball", "throws something forward", "throws overhand"],
    "duck": ["runs and ducks under an obstacle", "ducks down", "ducks under a bar"],
    "grab-high": ["reaches up to grab something high", "grabs something from a high shelf", "reaches high above the head"],
    "sneak": ["sneaks forward", "tiptoes forward quietly", "sneaks around"],
}

STYLES = [
    ("happy", "happy"), ("sad", "sad"), ("angry", "angry"), ("proud", "proud"),
    ("shy", "unconfident"), ("masculine", "masculine"), ("feminine", "feminine"),
    ("young", "childish"), ("old", "elderly"), ("tired", "exhausted"),
    ("energetic", "active"), ("theatrical", "musical"), ("giant", "heavy"),
    ("swaggering", "thuggish"),
]


def captions():
    """(caption, class) pairs, deduplicated, in a fixed order."""
    out = {}
    for cls, acts in ACTIONS.items():
        for i, act in enumerate(acts):
            for subject in ("a person", "someone", "a man"):
                out.setdefault(f"{subject} {act}", cls)
            for adj, manner in STYLES:
                out.setdefault(f"a {adj} person {act}", cls)
                out.setdefault(f"someone {act} in a {manner} way", cls)
    return list(out.items())


PARAPHRASES = [
    ("a person strolls", {"walk"}),
    ("someone strolls along slowly", {"walk"}),
    ("a man ambles ahead", {"walk"}),
    ("someone jogs ahead", {"run"}),
    ("a person hurries forward", {"run", "dash"}),
    ("a person sprints as fast as they can", {"dash", "run"}),
    ("a person elevates both arms", {"raise-both"}),
    ("someone lifts the right arm up high", {"raise-right"}),
    ("a person leaps into the air", {"jump", "hop"}),
    ("someone hops up and down on one foot", {"hop"}),
    ("a man kicks forward with his right leg", {"kick"}),
    ("someone crouches down low", {"squat", "duck"}),
    ("a person bends the knees deeply and rises again", {"squat"}),
    ("a person takes a seat", {"sit"}),
    ("someone sits down on a chair", {"sit"}),
    ("a person grabs something off the floor", {"pick-up"}),
    ("someone bends over to lift a box from the ground", {"pick-up"}),
    ("a person lies flat on the ground", {"lie-down"}),
    ("a person turns to the left while walking", {"walk-turn-left"}),
    ("someone veers right as they walk", {"walk-turn-right"}),
    ("a person waves hello", {"bye", "byebye", "wave-both", "wave-left", "wave-right"}),
    ("someone greets with a wave of the right hand", {"wave-right", "bye"}),
    ("a man bows politely", {"bow"}),
    ("someone throws a jab", {"punch"}),
    ("a person boxes the air", {"punch"}),
    ("someone dances happily", {"dance"}),
    ("a person moves to the music", {"dance"}),
    ("a person backs up", {"walk-back"}),
    ("a person sidesteps to the left", {"walk-left"}),
    ("someone climbs up a wall", {"climb"}),
    ("a person crawls on all fours", {"crawl"}),
    ("a person tosses a ball", {"throw"}),
    ("someone ducks under something", {"duck"}),
    ("a person stands up from the floor", {"get-up"}),
]

# Prompts no caption describes: text that is not motion, and motions outside the data.
UNRELATED = [
    "a cat sleeps on the sofa", "the stock market fell today", "bake the bread for an hour",
    "a red car parked outside", "the weather is cloudy", "please send me the invoice",
    "a bowl of hot soup", "purple", "hello world", "qwerty asdf",
]
OUT_OF_DATA = [
    "a person plays the piano", "someone swims in a pool", "a person rides a bicycle",
    "someone types on a keyboard", "a person drives a car", "someone juggles three balls",
]


if __name__ == "__main__":
    for caption, _ in captions():
        print(caption)
