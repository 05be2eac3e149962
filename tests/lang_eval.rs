//! Evaluation tests: for every operator, builtin and library function, the error on a
//! small synthetic motion equals a value computed by hand (in f64, independently of the
//! evaluator), and the burn gradient equals central finite differences.

mod lang_common;

use lang_common::*;
use mprog::skeleton::SEGMENTS;

const F: usize = 12;

type Reference = fn(&Motion) -> f64;

fn p(m: &Motion, person: usize, t: usize, j: usize) -> [f64; 3] {
    m[person][t][j]
}

/// Mean over all frames of `f(t)` for person 0.
fn over_all(f: impl Fn(usize) -> f64) -> f64 {
    mean((0..F).map(f))
}

fn vel(m: &Motion, t: usize, j: usize) -> [f64; 3] {
    let hi = (t + 1).min(F - 1);
    scale(sub(p(m, 0, hi, j), p(m, 0, hi - 1, j)), 20.0)
}

fn acc(m: &Motion, t: usize, j: usize) -> [f64; 3] {
    let b = t.min(F - 3);
    let d = add(
        sub(p(m, 0, b + 2, j), scale(p(m, 0, b + 1, j), 2.0)),
        p(m, 0, b, j),
    );
    scale(d, 400.0)
}

fn normalize(v: [f64; 3]) -> [f64; 3] {
    scale(v, 1.0 / norm(v))
}

fn mass_center(m: &Motion, person: usize, t: usize, head: bool) -> [f64; 3] {
    let mut acc = [0.0; 3];
    let mut total = 0.0;
    for s in SEGMENTS {
        let w = if !head && s.a == 12 && s.b == 15 {
            0.0
        } else {
            f64::from(s.weight)
        };
        let mid = scale(add(p(m, person, t, s.a), p(m, person, t, s.b)), 0.5);
        acc = add(acc, scale(mid, w));
        total += w;
    }
    scale(acc, 1.0 / total)
}

fn facing(m: &Motion, person: usize, t: usize) -> [f64; 3] {
    let hips = normalize(sub(p(m, person, t, 2), p(m, person, t, 1)));
    let sh = normalize(sub(p(m, person, t, 17), p(m, person, t, 16)));
    let across = normalize(add(hips, sh));
    normalize(cross([0.0, 1.0, 0.0], across))
}

fn seg_dist(q: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let ab = sub(b, a);
    let t = (dot(sub(q, a), ab) / dot(ab, ab)).clamp(0.0, 1.0);
    norm(sub(q, add(a, scale(ab, t))))
}

/// Signed distance of `q`'s ground projection to the convex hull of the feet (monotone
/// chain hull, an algorithm independent of the evaluator's).
fn support_dist(m: &Motion, t: usize, q: [f64; 3]) -> f64 {
    let mut pts: Vec<[f64; 2]> = [7, 10, 8, 11]
        .iter()
        .map(|&j| [p(m, 0, t, j)[0], p(m, 0, t, j)[2]])
        .collect();
    pts.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let cr = |o: [f64; 2], a: [f64; 2], b: [f64; 2]| {
        (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
    };
    let mut hull: Vec<[f64; 2]> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Vec<[f64; 2]> = if pass == 0 {
            pts.clone()
        } else {
            pts.iter().rev().copied().collect()
        };
        for pt in iter {
            while hull.len() >= start + 2
                && cr(hull[hull.len() - 2], hull[hull.len() - 1], pt) <= 0.0
            {
                hull.pop();
            }
            hull.push(pt);
        }
        hull.pop();
    }
    let g = [q[0], q[2]];
    let mut inside = true;
    let mut d = f64::INFINITY;
    for i in 0..hull.len() {
        let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
        if cr(a, b, g) < 0.0 {
            inside = false;
        }
        d = d.min(seg_dist(
            [g[0], 0.0, g[1]],
            [a[0], 0.0, a[1]],
            [b[0], 0.0, b[1]],
        ));
    }
    if inside { -d } else { d }
}

fn angle(u: [f64; 3], v: [f64; 3]) -> f64 {
    norm(cross(u, v)).atan2(dot(u, v))
}

fn cases() -> Vec<(&'static str, usize, &'static str, Reference)> {
    vec![
        ("eq scalar", 1, "always { head.y == 1.6 m }", |m| {
            over_all(|t| (p(m, 0, t, 15)[1] - 1.6).abs())
        }),
        ("eq vector", 1, "always { l_hand == r_hand }", |m| {
            over_all(|t| norm(sub(p(m, 0, t, 20), p(m, 0, t, 21))))
        }),
        ("lt", 1, "always { head.y < 1.5 m }", |m| {
            over_all(|t| relu(p(m, 0, t, 15)[1] - 1.5))
        }),
        ("gt", 1, "always { pelvis.z > 50 cm }", |m| {
            over_all(|t| relu(0.5 - p(m, 0, t, 0)[2]))
        }),
        (
            "le ge",
            1,
            "always { head.y <= 1.5 m and pelvis.z >= 0.5 m }",
            |m| over_all(|t| relu(p(m, 0, t, 15)[1] - 1.5) + relu(0.5 - p(m, 0, t, 0)[2])),
        ),
        ("vector lt", 1, "always { r_hand < [0, 1, 0.3] }", |m| {
            over_all(|t| {
                let h = p(m, 0, t, 21);
                relu(h[0]) + relu(h[1] - 1.0) + relu(h[2] - 0.3)
            })
        }),
        (
            "or",
            1,
            "always { l_foot.y < 0.02 m or r_foot.y < 0.02 m }",
            |m| over_all(|t| relu(p(m, 0, t, 10)[1] - 0.02).min(relu(p(m, 0, t, 11)[1] - 0.02))),
        ),
        (
            "not",
            1,
            "always { not (dist(head, pelvis) < 0.3 m) }",
            |m| over_all(|t| -relu(norm(sub(p(m, 0, t, 15), p(m, 0, t, 0))) - 0.3)),
        ),
        (
            "weights",
            1,
            "always { head.y == 1.6 m weight 3 }\nweight 2 { at end weight 0.5 { pelvis.x == 0 } }",
            |m| 3.0 * over_all(|t| (p(m, 0, t, 15)[1] - 1.6).abs()) + p(m, 0, F - 1, 0)[0].abs(),
        ),
        (
            "minimize maximize",
            1,
            "minimize sq(head.y - 1.6 m)\nmaximize pelvis.z weight 0.1",
            |m| {
                over_all(|t| (p(m, 0, t, 15)[1] - 1.6).powi(2))
                    - 0.1 * over_all(|t| p(m, 0, t, 0)[2])
            },
        ),
        (
            "keyframes",
            1,
            "at start, mid, end { head.y == 1.5 m }\nat 0.25s { pelvis.y == 1 m }\nat 50% { head.x == 0 }",
            |m| {
                mean([0, 6, 11].map(|t| (p(m, 0, t, 15)[1] - 1.5).abs()))
                    + (p(m, 0, 5, 0)[1] - 1.0).abs()
                    + p(m, 0, 6, 15)[0].abs()
            },
        ),
        (
            "during",
            1,
            "during 2..5 { pelvis.x > 0 }\nduring 0.1s..end { head.z < 0.2 m }",
            |m| {
                mean((2..5).map(|t| relu(-p(m, 0, t, 0)[0])))
                    + mean((2..11).map(|t| relu(p(m, 0, t, 15)[2] - 0.2)))
            },
        ),
        (
            "nested time blocks",
            1,
            "during 0..6 { at 4, 10 { head.y == 1.5 m } }",
            |m| (p(m, 0, 4, 15)[1] - 1.5).abs(),
        ),
        (
            "at operator",
            1,
            "always { dist(pelvis, pelvis@0) > 0.5 m }\nat 3 { head == head@end - [0, 0, 0.1] }",
            |m| {
                over_all(|t| relu(0.5 - norm(sub(p(m, 0, t, 0), p(m, 0, 0, 0)))))
                    + norm(sub(
                        p(m, 0, 3, 15),
                        sub(p(m, 0, F - 1, 15), [0.0, 0.0, 0.1]),
                    ))
            },
        ),
        (
            "if else",
            1,
            "if head.z > 0.3 m { head.y < 1.5 m } else { head.y > 1.6 m }",
            |m| {
                let on: Vec<usize> = (0..F).filter(|&t| p(m, 0, t, 15)[2] > 0.3).collect();
                let off: Vec<usize> = (0..F).filter(|&t| p(m, 0, t, 15)[2] <= 0.3).collect();
                mean(on.iter().map(|&t| relu(p(m, 0, t, 15)[1] - 1.5)))
                    + mean(off.iter().map(|&t| relu(1.6 - p(m, 0, t, 15)[1])))
            },
        ),
        (
            "if and or",
            1,
            "if pelvis.z > 0.2 m and pelvis.z < 0.5 m or head.x < -0.04 m { r_hand.y > 1.4 m }",
            |m| {
                let on: Vec<usize> = (0..F)
                    .filter(|&t| {
                        let z = p(m, 0, t, 0)[2];
                        (z > 0.2 && z < 0.5) || p(m, 0, t, 15)[0] < -0.04
                    })
                    .collect();
                mean(on.iter().map(|&t| relu(1.4 - p(m, 0, t, 21)[1])))
            },
        ),
        (
            "for list",
            1,
            "for j in [l_hand, r_hand, head] { always { j.y > 1.2 m } }",
            |m| {
                [20, 21, 15]
                    .iter()
                    .map(|&j| over_all(|t| relu(1.2 - p(m, 0, t, j)[1])))
                    .sum()
            },
        ),
        (
            "for joints",
            1,
            "for j in joints { always { j.x < 0.1 m } }",
            |m| {
                (0..22)
                    .map(|j| over_all(|t| relu(p(m, 0, t, j)[0] - 0.1)))
                    .sum()
            },
        ),
        (
            "for lane-free body",
            1,
            "for j in [head, neck] { at end { pelvis.y == 1 m } }",
            |m| 2.0 * (p(m, 0, F - 1, 0)[1] - 1.0).abs(),
        ),
        (
            "nested for with if",
            1,
            "for j in [l_hand, r_hand] { for k in [head, pelvis] { if j.y > 0.9 m { dist(j, k) > 0.6 m } } }",
            |m| {
                let mut total = 0.0;
                for j in [20, 21] {
                    for k in [15, 0] {
                        let on: Vec<usize> = (0..F).filter(|&t| p(m, 0, t, j)[1] > 0.9).collect();
                        if !on.is_empty() {
                            total += mean(
                                on.iter()
                                    .map(|&t| relu(0.6 - norm(sub(p(m, 0, t, j), p(m, 0, t, k))))),
                            );
                        }
                    }
                }
                total
            },
        ),
        (
            "vel speed",
            1,
            "always { norm(vel(pelvis)) < 1 }\nat 3 { speed(head) == 1 }",
            |m| over_all(|t| relu(norm(vel(m, t, 0)) - 1.0)) + (norm(vel(m, 3, 15)) - 1.0).abs(),
        ),
        ("acc", 1, "always { norm(acc(r_hand)) < 1 }", |m| {
            over_all(|t| relu(norm(acc(m, t, 21)) - 1.0))
        }),
        (
            "dot normalize",
            1,
            "always { dot(normalize(l_hand - r_hand), [1, 0, 0]) > 0.95 }",
            |m| over_all(|t| relu(0.95 - normalize(sub(p(m, 0, t, 20), p(m, 0, t, 21)))[0])),
        ),
        (
            "cross",
            1,
            "always { norm(cross(l_hand - pelvis, r_hand - pelvis)) == 0.01 }",
            |m| {
                over_all(|t| {
                    (norm(cross(
                        sub(p(m, 0, t, 20), p(m, 0, t, 0)),
                        sub(p(m, 0, t, 21), p(m, 0, t, 0)),
                    )) - 0.01)
                        .abs()
                })
            },
        ),
        (
            "clamp min max abs sqrt",
            1,
            "always { clamp(head.y, 1 m, 1.55 m) == 1.5 m }\nalways { min(l_hand.y, r_hand.y) > 1 m }\nalways { max(abs(l_hand.x), abs(r_hand.x)) < 0.3 m }\nalways { sqrt(dot(head - pelvis, head - pelvis)) == 0.6 m }",
            |m| {
                over_all(|t| {
                    let (h, l, r) = (p(m, 0, t, 15), p(m, 0, t, 20), p(m, 0, t, 21));
                    (h[1].clamp(1.0, 1.55) - 1.5).abs()
                        + relu(1.0 - l[1].min(r[1]))
                        + relu(l[0].abs().max(r[0].abs()) - 0.3)
                        + (norm(sub(h, p(m, 0, t, 0))) - 0.6).abs()
                })
            },
        ),
        (
            "atan2 sin cos",
            1,
            "always { atan2(r_hand.y - r_shoulder.y, r_hand.x - r_shoulder.x) == 45 deg }\nalways { sin(30 deg) * head.y > cos(10 deg) * pelvis.y }",
            |m| {
                over_all(|t| {
                    let (h, s) = (p(m, 0, t, 21), p(m, 0, t, 17));
                    ((h[1] - s[1]).atan2(h[0] - s[0]) - 45f64.to_radians()).abs()
                        + relu(
                            10f64.to_radians().cos() * p(m, 0, t, 0)[1] - 0.5 * p(m, 0, t, 15)[1],
                        )
                })
            },
        ),
        (
            "vec",
            1,
            "always { r_hand == vec(pelvis.x, 1.5 m, pelvis.z) }",
            |m| {
                over_all(|t| {
                    let pe = p(m, 0, t, 0);
                    norm(sub(p(m, 0, t, 21), [pe[0], 1.5, pe[2]]))
                })
            },
        ),
        (
            "bone boneDir parent",
            1,
            "always { boneDir(l_elbow, [1, 0, 1]) }\nat 2 { norm(bone(r_wrist)) == 0.3 m }",
            |m| {
                over_all(|t| angle(sub(p(m, 0, t, 18), p(m, 0, t, 16)), [1.0, 0.0, 1.0]))
                    + (norm(sub(p(m, 0, 2, 21), p(m, 0, 2, 19))) - 0.3).abs()
            },
        ),
        (
            "massCtr",
            1,
            "always { massCtr().y == 0.9 m }\nat end { massCtrNoHead(me) == [0, 1, 0] }",
            |m| {
                over_all(|t| (mass_center(m, 0, t, true)[1] - 0.9).abs())
                    + norm(sub(mass_center(m, 0, F - 1, false), [0.0, 1.0, 0.0]))
            },
        ),
        (
            "supportDist balanced",
            1,
            "minimize supportDist(head)\nalways { balanced(me) }\nat 3 { supportDist([0.5, 0, 0.2]) == 0 }",
            |m| {
                over_all(|t| support_dist(m, t, p(m, 0, t, 15)))
                    + over_all(|t| relu(support_dist(m, t, mass_center(m, 0, t, true))))
                    + support_dist(m, 3, [0.5, 0.0, 0.2]).abs()
            },
        ),
        (
            "facing",
            1,
            "always { dot(facing(), [0.3, 0, 1]) > 0.99 }",
            |m| over_all(|t| relu(0.99 - dot(facing(m, 0, t), [0.3, 0.0, 1.0]))),
        ),
        (
            "geometry library",
            1,
            "always { distToLine(l_foot, [0.5, 0.1, 0.4], [0.4, 0, 1]) < 5 cm }\nalways { distToSegment(r_hand, pelvis, neck) > 0.3 m }\nalways { distToPlane(r_hand, [-1, 0, 0], [1, 0, 0.25]) == 0 }\nalways { signedDistToPlane(head, [0, 1.8, 0], [0, 1, 0]) < -0.3 m }",
            |m| {
                over_all(|t| {
                    let f = p(m, 0, t, 10);
                    let d = [0.4, 0.0, 1.0];
                    let line = norm(cross(sub(f, [0.5, 0.1, 0.4]), d)) / norm(d);
                    let seg = seg_dist(p(m, 0, t, 21), p(m, 0, t, 0), p(m, 0, t, 12));
                    let n = [1.0, 0.0, 0.25];
                    let plane = (dot(sub(p(m, 0, t, 21), [-1.0, 0.0, 0.0]), n) / norm(n)).abs();
                    let signed = p(m, 0, t, 15)[1] - 1.8;
                    relu(line - 0.05) + relu(0.3 - seg) + plane + relu(signed + 0.3)
                })
            },
        ),
        (
            "points library",
            1,
            "always { dist(midPoint(l_hand, r_hand), chest) > 0.3 m }\nat mid { pelvis == lerp(pelvis@start, pelvis@end, 0.5) }\nalways { groundDist(pelvis, [0, 5, 0.2]) < 0.1 m }\nalways { projToGround(head) == [0, 0, 0.3] }\nalways { angle(r_hand - r_shoulder, up) < 20 deg }",
            |m| {
                let mid = over_all(|t| {
                    relu(
                        0.3 - norm(sub(
                            scale(add(p(m, 0, t, 20), p(m, 0, t, 21)), 0.5),
                            p(m, 0, t, 9),
                        )),
                    )
                });
                let lerp = norm(sub(
                    p(m, 0, 6, 0),
                    scale(add(p(m, 0, 0, 0), p(m, 0, F - 1, 0)), 0.5),
                ));
                let ground = over_all(|t| {
                    let pe = p(m, 0, t, 0);
                    relu(norm([pe[0], 0.0, pe[2] - 0.2]) - 0.1)
                });
                let proj = over_all(|t| {
                    let h = p(m, 0, t, 15);
                    norm([h[0], 0.0, h[2] - 0.3])
                });
                let ang = over_all(|t| {
                    relu(
                        angle(sub(p(m, 0, t, 21), p(m, 0, t, 17)), [0.0, 1.0, 0.0])
                            - 20f64.to_radians(),
                    )
                });
                mid + lerp + ground + proj + ang
            },
        ),
        (
            "regions",
            1,
            "always { inBox(pelvis, [-1, 0.9, -1], [1, 2, 0.4]) }\nfor j in [head, r_foot] { always { inSquare(j, [0, 0, 0.1], 0.2 m) } }",
            |m| {
                let boxed = over_all(|t| {
                    let q = p(m, 0, t, 0);
                    let lo = [-1.0, 0.9, -1.0];
                    let hi = [1.0, 2.0, 0.4];
                    (0..3)
                        .map(|c| relu(lo[c] - q[c]) + relu(q[c] - hi[c]))
                        .sum()
                });
                let sq: f64 = [15, 11]
                    .iter()
                    .map(|&j| {
                        over_all(|t| {
                            relu(p(m, 0, t, j)[0].abs() - 0.2)
                                + relu((p(m, 0, t, j)[2] - 0.1).abs() - 0.2)
                        })
                    })
                    .sum();
                boxed + sq
            },
        ),
        ("footHeight", 1, "always { footHeight(me) < 1 cm }", |m| {
            over_all(|t| {
                relu(
                    [10, 11, 7, 8]
                        .iter()
                        .map(|&j| p(m, 0, t, j)[1])
                        .fold(f64::INFINITY, f64::min)
                        - 0.01,
                )
            })
        }),
        (
            "two people",
            2,
            "people a \"a person waves\", b \"a person waves back\"\nduring 2..6 { contact(a.r_hand, b.l_hand, 5 cm) }\nalways { apart(a.head, b.head, 1.2 m) }\nalways { separation(a, b, 1.4 m) }\nfor q in people { always { q.head.y > 1.6 m } }",
            |m| {
                let contact =
                    mean((2..6).map(|t| relu(norm(sub(p(m, 0, t, 21), p(m, 1, t, 20))) - 0.05)));
                let apart = over_all(|t| relu(1.2 - norm(sub(p(m, 0, t, 15), p(m, 1, t, 15)))));
                let sep = over_all(|t| {
                    let d = sub(p(m, 0, t, 0), p(m, 1, t, 0));
                    relu(1.4 - norm([d[0], 0.0, d[2]]))
                });
                let heads: f64 = (0..2)
                    .map(|q| over_all(|t| relu(1.6 - p(m, q, t, 15)[1])))
                    .sum();
                contact + apart + sep + heads
            },
        ),
        (
            "face to face and torsos",
            2,
            "people a, b\nalways { faceToFace(a, b) }\nalways { noTorsoCollision(a, b, 1.2 m) }",
            |m| {
                let ftf = over_all(|t| {
                    let (fa, fb) = (facing(m, 0, t), facing(m, 1, t));
                    let d = sub(p(m, 1, t, 0), p(m, 0, t, 0));
                    relu(norm(add(fa, fb)) - 0.2)
                        + relu(0.8 - dot(fa, normalize([d[0], 0.0, d[2]])))
                });
                let torso = over_all(|t| {
                    let mut e = 0.0;
                    for (x, y) in [(0, 1), (1, 0)] {
                        for j in [0, 9, 12] {
                            e += relu(1.2 - seg_dist(p(m, y, t, j), p(m, x, t, 0), p(m, x, t, 12)));
                        }
                    }
                    e
                });
                ftf + torso
            },
        ),
        (
            "three people loops",
            3,
            "people a, b, c\nfor q in [a, c] { for j in [l_hand, r_hand] { at end { q.j.y > 1.5 m } } }\nalways { massCtr(b).y > 1 m }",
            |m| {
                let mut total = 0.0;
                for q in [0, 2] {
                    for j in [20, 21] {
                        total += relu(1.5 - p(m, q, F - 1, j)[1]);
                    }
                }
                total + over_all(|t| relu(1.0 - mass_center(m, 1, t, true)[1]))
            },
        ),
        (
            "a def sees the lets above it",
            1,
            "let tall = 1.6 m\ndef atHeight(j) = j.y == tall\nalways { atHeight(head) }",
            |m| over_all(|t| (p(m, 0, t, 15)[1] - 1.6).abs()),
        ),
        (
            "time",
            1,
            "always { head.y == 1.5 m + 0.5 m/s * time }\nat end { pelvis.z == 1 m/s * time@0.25s }",
            |m| {
                over_all(|t| (p(m, 0, t, 15)[1] - (1.5 + 0.5 * t as f64 / 20.0)).abs())
                    + (p(m, 0, F - 1, 0)[2] - 0.25).abs()
            },
        ),
        (
            "time in trig and conditions",
            1,
            "always { r_hand.x == 0.3 * cos(180 deg/s * time) }\nif time > 0.3s { head.y > 1.7 m }",
            |m| {
                let w = std::f64::consts::PI;
                over_all(|t| (p(m, 0, t, 21)[0] - 0.3 * (w * t as f64 / 20.0).cos()).abs())
                    + mean((7..F).map(|t| relu(1.7 - p(m, 0, t, 15)[1])))
            },
        ),
        (
            "body axes and gaze",
            1,
            "always { bodyFront() == [0, 0, 1] }\nalways { dot(bodyLeft(), [1, 0, 0]) > 1 }\nat end { bodyUp() == [0, 1, 0] }\nalways { gaze() == [0, 0, 1] }",
            |m| {
                let last = body_axes(m, 0, F - 1);
                over_all(|t| norm(sub(body_axes(m, 0, t)[2], [0.0, 0.0, 1.0])))
                    + over_all(|t| relu(1.0 - body_axes(m, 0, t)[0][0]))
                    + norm(sub(last[1], [0.0, 1.0, 0.0]))
                    + over_all(|t| norm(sub(gaze(m, 0, t), [0.0, 0.0, 1.0])))
            },
        ),
        (
            "body axes of people",
            2,
            "people a, b\nalways { dot(bodyFront(a), bodyFront(b)) > 0 }\nalways { gaze(b).y > 0 }",
            |m| {
                over_all(|t| relu(-dot(body_axes(m, 0, t)[2], body_axes(m, 1, t)[2])))
                    + over_all(|t| relu(-gaze(m, 1, t)[1]))
            },
        ),
    ]
}

/// The torso's frame `[left, up, front]` of `person` at frame `t`.
fn body_axes(m: &Motion, person: usize, t: usize) -> [[f64; 3]; 3] {
    let j = |k| p(m, person, t, k);
    let across = add(normalize(sub(j(1), j(2))), normalize(sub(j(16), j(17))));
    let up = normalize(sub(j(12), j(0)));
    let front = normalize(cross(across, up));
    [cross(up, front), up, front]
}

/// The head's direction: perpendicular to the shoulders and the neck→head bone, raised 25°.
fn gaze(m: &Motion, person: usize, t: usize) -> [f64; 3] {
    let j = |k| p(m, person, t, k);
    let l = normalize(sub(j(16), j(17)));
    let g0 = normalize(cross(l, sub(j(15), j(12))));
    let (s, c) = 25f64.to_radians().sin_cos();
    add(scale(g0, c), scale(cross(g0, l), s))
}

/// The rest pose (facing +Z, left at +X) with the head level: the neck→head bone leaning
/// 25° forward, as in HumanML3D's upright frames.
fn standing() -> [[f64; 3]; 22] {
    let rest = mprog::skeleton::rest_pose();
    let mut pose: [[f64; 3]; 22] =
        std::array::from_fn(|j| [rest[j].x, rest[j].y, rest[j].z].map(f64::from));
    let (s, c) = 25f64.to_radians().sin_cos();
    pose[15] = add(pose[12], [0.0, 0.103 * c, 0.103 * s]);
    // Level shoulders (the rest offsets put the right one 9 mm higher).
    pose[17][1] = pose[16][1];
    pose
}

/// Total error of `body` (after a length line) on `frames` copies of `pose(t)`.
fn error_on(body: &str, pose: impl Fn(usize) -> [[f64; 3]; 22]) -> f64 {
    let prog = program(&format!("length {F} frames\n{body}\n"));
    let m: Motion = vec![(0..F).map(pose).collect()];
    let (data, shape) = flat(&m);
    eval(&prog, &data, shape).0
}

#[test]
fn body_axes_of_the_rest_pose_and_of_lying_on_the_back() {
    let axes = "always { bodyFront() == [0, 0, 1] and bodyLeft() == [1, 0, 0] and bodyUp() == [0, 1, 0] and gaze() == [0, 0, 1] }";
    assert!(error_on(axes, |_| standing()) < 1e-5);
    // Lying on the back, head towards -Z: the rest pose turned 90° about X (y → z, z → -y).
    let lying = |_| standing().map(|[x, y, z]| [x, z, -y]);
    let on_back = "always { bodyFront() == [0, 1, 0] and bodyLeft() == [1, 0, 0] and bodyUp() == [0, 0, -1] }";
    assert!(error_on(on_back, lying) < 1e-5);
    // Standing, the same program is wrong by about two right angles' chords.
    assert!(error_on(on_back, |_| standing()) > 2.0);
}

#[test]
fn gaze_follows_the_upper_body_turning_and_the_head_tipping() {
    // Looking over the left shoulder, as far as joints show it: everything above the
    // middle of the spine turned 60° to the left (towards +X) about the vertical.
    let (s, c) = 60f64.to_radians().sin_cos();
    let turned = |_| {
        let mut pose = standing();
        let pivot = pose[9];
        for j in [9, 12, 13, 14, 15, 16, 17, 18, 19, 20, 21] {
            let [x, y, z] = sub(pose[j], pivot);
            pose[j] = add(pivot, [x * c + z * s, y, -x * s + z * c]);
        }
        pose
    };
    let over_left = "always { gaze() == [0.8660254, 0, 0.5] }";
    assert!(error_on(over_left, turned) < 1e-4);
    assert!(error_on(over_left, |_| standing()) > 0.5);
    // Tipping the head 30° forward (chin to chest) looks 30° down.
    let (s30, c30) = 30f64.to_radians().sin_cos();
    let nodding = |_| {
        let mut pose = standing();
        let (s, c) = 55f64.to_radians().sin_cos();
        pose[15] = add(pose[12], [0.0, 0.103 * c, 0.103 * s]);
        pose
    };
    let down = format!("always {{ gaze() == [0, {}, {}] }}", -s30, c30);
    assert!(error_on(&down, nodding) < 1e-4);
}

#[test]
fn time_drives_a_circle_met_exactly_by_a_motion_made_for_it() {
    // The right wrist goes round a 30 cm circle at 1.2 m, half a turn per second.
    let circle = "always { dist(r_hand, [0.3*cos(180 deg/s * time), 1.2, 0.3*sin(180 deg/s * time)]) < 5 mm }";
    let on_circle = |t: usize| {
        let mut pose = standing();
        let a = std::f64::consts::PI * t as f64 / 20.0;
        pose[21] = [0.3 * a.cos(), 1.2, 0.3 * a.sin()];
        pose
    };
    assert!(error_on(circle, on_circle) < 1e-6);
    // A quarter turn late is wrong on every frame.
    let late = |t: usize| on_circle(t + 10);
    assert!(error_on(circle, late) > 0.3);
    // `time` carries no gradient of its own: the circle's gradient is the wrist's.
    let prog = program(&format!("length {F} frames\n{circle}\n"));
    let m: Motion = vec![(0..F).map(late).collect()];
    check_gradient(&prog, &m, "time circle");
}

#[test]
fn errors_match_hand_computed_values() {
    for (name, people, body, reference) in cases() {
        let src = format!("length {F} frames\n{body}\n");
        let prog = program(&src);
        let m = motion(people, F);
        let (data, shape) = flat(&m);
        let (total, per) = eval(&prog, &data, shape);
        let expected = reference(&m);
        assert!(
            (total - expected).abs() <= 1e-4 * (1.0 + expected.abs()),
            "{name}: evaluator {total} vs hand-computed {expected}"
        );
        let sum: f64 = per.iter().sum();
        assert!(
            (sum - total).abs() <= 1e-4 * (1.0 + total.abs()),
            "{name}: breakdown does not add up"
        );
        assert_eq!(
            per.len(),
            prog.statements().len(),
            "{name}: one column per statement"
        );
    }
}

#[test]
fn gradients_match_finite_differences() {
    for (name, people, body, _) in cases() {
        let src = format!("length {F} frames\n{body}\n");
        let prog = program(&src);
        check_gradient(&prog, &motion(people, F), name);
    }
}

#[test]
fn batches_are_independent() {
    let prog = program("length 12 frames\nalways { head.y == 1.6 m }\nat end { pelvis.z > 1 m }");
    let a = motion(1, F);
    let mut b = motion(1, F);
    for f in &mut b[0] {
        for j in f.iter_mut() {
            j[1] += 0.2;
        }
    }
    let (da, _) = flat(&a);
    let (db, _) = flat(&b);
    let single_a = eval(&prog, &da, [1, 1, F, 22, 3]).0;
    let single_b = eval(&prog, &db, [1, 1, F, 22, 3]).0;
    let both: Vec<f32> = da.iter().chain(&db).copied().collect();
    let dev = burn::tensor::Device::flex();
    let x = burn::tensor::Tensor::<5>::from_data(
        burn::tensor::TensorData::new(both, [2, 1, F, 22, 3]),
        &dev,
    );
    let e = prog.evaluate(x);
    let totals = e.total.into_data().try_into_vec::<f32>().unwrap();
    assert!((f64::from(totals[0]) - single_a).abs() < 1e-5);
    assert!((f64::from(totals[1]) - single_b).abs() < 1e-5);
    assert_eq!(e.per_statement.dims(), [2, 2]);
}

#[test]
fn wrong_shapes_are_reported_not_panicking() {
    let prog = program("length 12 frames\nalways { head.y == 1.6 m }");
    let dev = burn::tensor::Device::flex();
    let x = burn::tensor::Tensor::<5>::zeros([1, 2, F, 22, 3], &dev);
    assert!(prog.try_evaluate(x).is_err());
    let x = burn::tensor::Tensor::<5>::zeros([1, 1, F, 21, 3], &dev);
    assert!(prog.try_evaluate(x).is_err());
}

#[test]
fn a_window_counts_only_the_frames_made_so_far() {
    use burn::prelude::*;
    use mprog::solve::MotionError;
    // Head 1 m too low on every frame: 1 m of error for `always`, for `at 30`, and for
    // `during 10..40`, on a motion of 60 frames.
    const N: usize = 60;
    let prog = program(&format!(
        "length {N} frames\nalways {{ head.y > 2.5 m }}\nat 30 {{ head.y > 2.5 m }}\nduring 10..40 {{ head.y > 2.5 m }}\n"
    ));
    let m: Motion = vec![(0..N).map(|_| standing()).collect()];
    let (data, shape) = flat(&m);
    let joints = || Tensor::<5>::from_data(TensorData::new(data.clone(), shape), &Device::flex());
    let terms = |until: usize| -> Vec<f32> {
        prog.terms_until(joints(), until)
            .into_data()
            .try_into_vec::<f32>()
            .unwrap()
    };
    let full = terms(N);
    let whole = prog
        .terms(joints())
        .into_data()
        .try_into_vec::<f32>()
        .unwrap();
    assert_eq!(full, whole, "until the end is the plain evaluation");
    // Before frame 20: `always` counts frames 0..20 (the same mean), `at 30` nothing, the
    // `during` its frames 10..20 (the same mean again).
    let before = terms(20);
    assert!((before[0] - full[0]).abs() < 1e-5 && (before[2] - full[2]).abs() < 1e-5);
    assert_eq!(before[1], 0.0);
    assert!(full[1] > 0.9);
    // Before frame 5 the `during` has no frame yet.
    assert_eq!(terms(5)[2], 0.0);
    // The error counts only those frames: raising the head after frame 20 changes nothing.
    let mut raised = m.clone();
    for pose in &mut raised[0][20..] {
        for j in pose.iter_mut() {
            j[1] += 3.0;
        }
    }
    let (data2, _) = flat(&raised);
    let t2 = Tensor::<5>::from_data(TensorData::new(data2, shape), &Device::flex());
    let after: Vec<f32> = prog
        .terms_until(t2, 20)
        .into_data()
        .try_into_vec::<f32>()
        .unwrap();
    assert_eq!(after, before);
}
