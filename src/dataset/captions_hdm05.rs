//! Captions of HDM05 "cut" clips from their class, the third field of the file name
//! (`HDM_bd_squat1Reps_001_120`) and the name of the folder the archive keeps them in.
//! Sides are the actor's: `kickLFront` kicks with the left leg.

/// Sentences for an HDM05 class; empty when the class is unknown.
pub fn hdm05_captions(class: &str) -> Vec<String> {
    let phrases: &[&str] = match class {
        "squat1Reps" | "squat3Reps" => &[
            "squats down and stands back up",
            "does a squat",
            "crouches down low and stands up again",
        ],
        "depositFloorR" => &[
            "bends down and puts something on the floor with the right hand",
            "puts an object down on the floor with the right hand",
            "squats down to place something on the floor and stands back up",
        ],
        "grabFloorR" => &[
            "picks something up from the floor with the right hand",
            "bends down and picks up an object from the floor",
            "reaches down to the floor and picks something up",
        ],
        "kickLFront1Reps" | "kickLFront2Reps" => &[
            "kicks forward with the left leg",
            "does a front kick with the left foot",
            "kicks the left leg forward and puts it back down",
        ],
        "kickRFront1Reps" | "kickRFront2Reps" => &[
            "kicks forward with the right leg",
            "does a front kick with the right foot",
            "kicks the right leg forward and puts it back down",
        ],
        "lieDownFloor" => &[
            "lies down on the floor",
            "gets down and lies on the floor",
            "goes from standing to lying on the ground",
        ],
        // Each hop travels about a metre: standing long jumps, not jumps in place.
        "hopBothLegs1hops" | "hopBothLegs2hops" | "hopBothLegs3hops" => &[
            "jumps forward with both feet together",
            "hops forward on both feet",
            "does standing long jumps forward",
        ],
        "grabHighR" => &[
            "reaches up high with the right hand and grabs something",
            "grabs something above the head with the right hand",
            "stretches the right arm up to take something from a high shelf",
        ],
        "elbowToKnee1RepsLelbowStart" | "elbowToKnee3RepsLelbowStart" => &[
            "touches each knee with the opposite elbow",
            "lifts a knee to meet the opposite elbow, starting with the left elbow",
            "does elbow to knee crunches while standing",
        ],
        "jogLeftCircle4StepsRstart" | "jogLeftCircle6StepsRstart" => &[
            "jogs in a circle to the left",
            "runs slowly around in a left turn",
            "jogs counterclockwise in a small circle",
        ],
        "rotateArmsBothBackward1Reps" | "rotateArmsBothBackward3Reps" => &[
            "circles both arms backwards",
            "rotates both arms backward",
            "swings both arms around in backward circles",
        ],
        "sneak2StepsLStart" | "sneak4StepsLStart" => &[
            "sneaks forward quietly",
            "tiptoes forward carefully",
            "walks forward stealthily",
        ],
        "throwBasketball" => &[
            "throws a basketball",
            "shoots a basketball with both hands",
            "throws a ball forward with both hands",
        ],
        _ => &[],
    };
    let subjects = ["a person", "someone", "a man"];
    phrases
        .iter()
        .zip(subjects.iter().cycle())
        .map(|(p, s)| format!("{s} {p}"))
        .collect()
}

/// The class of an HDM05 file stem `HDM_<actor>_<class>_<nnn>[_<fps>]`.
pub fn hdm05_class(stem: &str) -> Option<&str> {
    let mut parts = stem.split('_');
    (parts.next()? == "HDM").then_some(())?;
    parts.next()?;
    let class = parts.next()?;
    parts.next()?.parse::<u32>().ok()?;
    Some(class)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes_from_names_and_captions() {
        assert_eq!(hdm05_class("HDM_bd_squat1Reps_001_120"), Some("squat1Reps"));
        assert_eq!(hdm05_class("HDM_bd"), None);
        assert_eq!(hdm05_class("dataset-1_walk_normal_001"), None);
        let c = hdm05_captions("squat1Reps");
        assert_eq!(c[0], "a person squats down and stands back up");
        assert!(hdm05_captions("kickLFront1Reps")[0].contains("left leg"));
        assert!(hdm05_captions("unknownClass").is_empty());
    }
}
