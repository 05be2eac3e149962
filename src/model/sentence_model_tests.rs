//! A denoiser conditioned on the frozen sentence encoder: a run started from a
//! bag-of-words bundle keeps every other weight, its bundle names the encoder and is
//! refused with another one, and the bundle tells when a prompt is far from its captions.

use super::config::{ModelConfig, TextEncoderKind, TrainConfig};
use super::denoiser::Mdm;
use super::prompt::PromptEncoder;
use super::sentence::{SentenceEncoder, default_encoder_dir};
use super::tests::{synthetic_dataset, tiny};
use super::train::TrainRun;
use super::weights::ModelBundle;
use burn::prelude::*;
use burn::store::ModuleSnapshot;
use std::collections::BTreeMap;
use std::path::Path;

fn sentence_tiny() -> ModelConfig {
    ModelConfig {
        d_text: 384,
        text_encoder: TextEncoderKind::Sentence,
        ..tiny()
    }
}

fn tensors(m: &Mdm) -> BTreeMap<String, Vec<f32>> {
    m.collect(None, None, false)
        .iter()
        .map(|t| {
            let data = burn::store::bridge::to_data(t).unwrap();
            (t.name.clone(), data.try_to_vec::<f32>().unwrap())
        })
        .collect()
}

fn train(out: &Path, model: ModelConfig, init: Option<&Path>, lr: f64, steps: usize) {
    let data = synthetic_dataset();
    TrainRun {
        data: &data,
        config: TrainConfig {
            model,
            batch_size: 2,
            crop_frames: 8,
            learning_rate: lr,
            warmup_steps: 1,
            checkpoint_every: 5,
            steps: 100,
            ..TrainConfig::default()
        },
        out: out.to_path_buf(),
        max_steps_now: Some(steps),
        interrupt: Default::default(),
        init_from: init.map(Path::to_path_buf),
        device: Device::flex(),
        after_checkpoint: None,
        text_encoder: None,
    }
    .run(&|_, _, _| {})
    .unwrap();
}

#[test]
fn a_bag_of_words_bundle_starts_a_sentence_run_with_its_other_weights() {
    let dev = Device::flex();
    let bag_dir = tempfile::tempdir().unwrap();
    train(bag_dir.path(), tiny(), None, 1e-3, 5);
    let bag = ModelBundle::load(&bag_dir.path().join("bundle"), &dev).unwrap();
    // A learning rate of ~0 keeps the carried weights where they were.
    let run_dir = tempfile::tempdir().unwrap();
    let init = bag_dir.path().join("bundle");
    train(run_dir.path(), sentence_tiny(), Some(&init), 1e-12, 5);
    let bundle_dir = run_dir.path().join("bundle");
    let sentence = ModelBundle::load(&bundle_dir, &dev).unwrap();
    assert_eq!(sentence.manifest.steps, 10, "the bundle's steps carry on");
    let encoder = SentenceEncoder::load(&default_encoder_dir(), &dev).unwrap();
    assert_eq!(
        sentence.manifest.text_encoder_id.as_deref(),
        Some(encoder.id())
    );
    let PromptEncoder::Sentences(s) = &sentence.text else {
        panic!("a sentence-encoder bundle reads prompts with the sentence encoder")
    };
    assert_eq!(
        s.captions.captions(),
        ["a person walks forward", "a person waves"]
    );
    let (old, new) = (tensors(&bag.model), tensors(&sentence.model));
    let mut carried = 0;
    for (name, value) in &new {
        if name.starts_with("text") {
            continue;
        }
        let before = &old[name];
        let diff = before
            .iter()
            .zip(value)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        // f16 bundles: one rounding step of the largest weights.
        assert!(diff < 2e-3, "{name} moved by {diff}");
        carried += 1;
    }
    assert!(carried > 10, "{carried} tensors compared");
    assert!(!new.keys().any(|k| k.starts_with("text.")), "no word table");
    assert_eq!(new["text_proj.weight"].len(), 384 * tiny().d_model);
}

#[test]
fn a_sentence_bundle_is_refused_with_another_encoder() {
    let dev = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    train(dir.path(), sentence_tiny(), None, 1e-3, 5);
    let bundle = dir.path().join("bundle");
    ModelBundle::load(&bundle, &dev).unwrap();
    let manifest = bundle.join("manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let id = ModelBundle::load(&bundle, &dev)
        .unwrap()
        .manifest
        .text_encoder_id
        .unwrap();
    std::fs::write(&manifest, text.replace(&id, "minilm-l6-0000000000000000")).unwrap();
    let err = ModelBundle::load(&bundle, &dev).unwrap_err().to_string();
    assert!(
        err.contains("text-encoder") && err.contains("trained with minilm-l6-0000000000000000"),
        "{err}"
    );
    std::fs::write(
        &manifest,
        text.replace(&format!("\"text_encoder_id\": \"{id}\""), "\"x\": 1"),
    )
    .unwrap();
    let err = ModelBundle::load(&bundle, &dev).unwrap_err().to_string();
    assert!(err.contains("text_encoder_id"), "{err}");
}

#[test]
fn far_prompts_are_reported_with_the_nearest_caption() {
    let dev = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    train(dir.path(), sentence_tiny(), None, 1e-3, 5);
    let mut bundle = ModelBundle::load(&dir.path().join("bundle"), &dev).unwrap();
    assert!(bundle.text.report("a person walks forward").is_empty());
    let budget = "the committee approved the annual budget";
    let far = bundle.text.report(budget);
    assert_eq!(far.len(), 2, "{far:?}");
    assert!(far[0].contains("nearest known: \"a person"), "{far:?}");
    // Read through its neighbours, and told so.
    assert!(
        far[1].contains("conditioned on the mean of its nearest captions, \"a person"),
        "{far:?}"
    );
    assert!(bundle.text.snapped(budget).is_some());
    bundle.text.read_literally();
    assert_eq!(bundle.text.report(budget).len(), 1);
    assert!(bundle.text.snapped(budget).is_none());
    assert!(bundle.text.unknown_words("someone moonwalks").is_empty());
}

#[test]
fn the_length_prior_gives_the_nearest_training_captions_length() {
    let dev = Device::flex();
    let dir = tempfile::tempdir().unwrap();
    train(dir.path(), sentence_tiny(), None, 1e-3, 5);
    let bundle_dir = dir.path().join("bundle");
    let bundle = ModelBundle::load(&bundle_dir, &dev).unwrap();
    // Only the training clip (24 frames, "a person walks forward") has a length; the
    // validation clip's caption ("a person waves") is never proposed.
    let (frames, nearest) = bundle
        .text
        .natural_frames("someone strolls ahead", 196)
        .unwrap();
    assert_eq!(
        (frames, nearest.caption.as_str()),
        (24, "a person walks forward")
    );
    let (_, nearest) = bundle.text.natural_frames("a person waves", 196).unwrap();
    assert_eq!(nearest.caption, "a person walks forward");
    assert_eq!(
        bundle.text.natural_frames("a person walks", 10).unwrap().0,
        10
    );
    // A bundle without lengths (older ones) proposes none; a broken file is named.
    let lengths = bundle_dir.join("lengths.json");
    let text = std::fs::read_to_string(&lengths).unwrap();
    assert!(
        text.contains("\"frames\": 24") && text.contains("\"clips\": 1"),
        "{text}"
    );
    std::fs::write(&lengths, text.replace("\"frames\": 24", "\"frames\": 0")).unwrap();
    let err = ModelBundle::load(&bundle_dir, &dev)
        .unwrap_err()
        .to_string();
    assert!(
        err.contains("lengths.json") && err.contains("length 0"),
        "{err}"
    );
    std::fs::remove_file(&lengths).unwrap();
    let old = ModelBundle::load(&bundle_dir, &dev).unwrap();
    assert!(old.text.natural_frames("a person walks", 196).is_none());
}

#[test]
fn a_training_batch_pairs_each_caption_with_its_side_swapped_one() {
    use super::lengths::CaptionLengths;
    use super::prompt::TextBatch;
    use super::sentence::CaptionIndex;
    use super::train::TrainText;
    let dev = Device::flex();
    let encoder = std::sync::Arc::new(SentenceEncoder::load(&default_encoder_dir(), &dev).unwrap());
    let captions = [
        "a person kicks the left leg forward",
        "a person kicks the right leg forward",
        "a person walks forward",
    ];
    let index = CaptionIndex::build(&encoder, &captions);
    let text = TrainText::sentences(
        encoder.clone(),
        index,
        CaptionLengths::of_dataset(&synthetic_dataset()),
    );
    // Known captions, and one the index lacks (word dropout's), whose swap it lacks too.
    let batch = text.batch(
        &[captions[0], captions[2], "a person raises the left hand"],
        &dev,
    );
    let TextBatch::Sentences(s) = batch else {
        panic!("a sentence batch")
    };
    let row = |t: &Tensor<2>, i: usize| t.clone().narrow(0, i, 1);
    let want = encoder.encode(&[captions[1], captions[2], "a person raises the right hand"]);
    let diff = (s.mirrored.clone() - want).abs().max().into_scalar::<f32>();
    assert!(diff < 1e-5, "{diff}");
    // A caption naming no side is its own swap: its side vector is exactly zero.
    let side = (row(&s.vectors, 1) - row(&s.mirrored, 1))
        .abs()
        .max()
        .into_scalar::<f32>();
    assert_eq!(side, 0.0);
}

#[test]
fn a_sentence_bundle_starts_a_run_with_the_side_input() {
    let dev = Device::flex();
    let base = tempfile::tempdir().unwrap();
    train(base.path(), sentence_tiny(), None, 1e-3, 5);
    let run = tempfile::tempdir().unwrap();
    let with_side = ModelConfig {
        side_input: true,
        ..sentence_tiny()
    };
    train(
        run.path(),
        with_side,
        Some(&base.path().join("bundle")),
        1e-3,
        5,
    );
    let bundle = ModelBundle::load(&run.path().join("bundle"), &dev).unwrap();
    assert!(bundle.config.side_input);
    assert_eq!(bundle.manifest.steps, 10);
    let names = tensors(&bundle.model);
    assert_eq!(names["side_proj.weight"].len(), 384 * tiny().d_model);
    assert!(!names.contains_key("side_proj.bias"));
}

#[test]
fn an_augmented_run_keeps_near_paraphrases_and_never_a_held_out_one() {
    use super::train::augment::{CaptionAugment, normalise};
    use super::train::paraphrase::paraphrases;
    let data = synthetic_dataset();
    let out = tempfile::tempdir().unwrap();
    // Hold out the first rule-made wording of the walk: it must never be trained on.
    let held = paraphrases("a person walks forward")[0].clone();
    let holdout = out.path().join("held.toml");
    std::fs::write(&holdout, format!("wordings = [\"{held}\"]\n")).unwrap();
    let config = TrainConfig {
        model: sentence_tiny(),
        batch_size: 2,
        crop_frames: 8,
        learning_rate: 1e-3,
        warmup_steps: 1,
        checkpoint_every: 3,
        steps: 100,
        paraphrase_prob: 0.5,
        paraphrases_per_caption: 4,
        paraphrase_holdout: Some(holdout.display().to_string()),
        text_noise: 0.02,
        hold_pad: 0.5,
        ..TrainConfig::default()
    };
    let run = |steps| {
        TrainRun {
            data: &data,
            config: config.clone(),
            out: out.path().to_path_buf(),
            max_steps_now: Some(steps),
            interrupt: Default::default(),
            init_from: None,
            device: Device::flex(),
            after_checkpoint: None,
            text_encoder: None,
        }
        .run(&|_, _, _| {})
        .unwrap()
    };
    assert_eq!(run(3).step, 3);
    let table = CaptionAugment::load_table(&out.path().join("paraphrases.json")).unwrap();
    let walks = &table["a person walks forward"];
    assert!(!walks.is_empty() && walks.len() <= 4, "{walks:?}");
    assert!(
        walks.iter().all(|w| normalise(w) != normalise(&held)),
        "{walks:?}"
    );
    // Resuming reads the table back instead of drawing it again.
    assert_eq!(run(3).step, 6);
    let again = CaptionAugment::load_table(&out.path().join("paraphrases.json")).unwrap();
    assert_eq!(table, again);
}

#[test]
fn an_unconditional_bundle_starts_the_text_controlnet_and_only_it_learns() {
    use super::denoiser::{Denoiser, DenoiserInput};
    use super::moc::MocConfig;
    use super::noise::NoiseSource;
    let dev = Device::flex();
    let prior_dir = tempfile::tempdir().unwrap();
    let prior_config = ModelConfig {
        side_input: true,
        input_skip: true,
        skip_taps: 3,
        skip_taps_below: Some(100),
        ..sentence_tiny()
    };
    train(prior_dir.path(), prior_config, None, 1e-3, 5);
    let prior = ModelBundle::load(&prior_dir.path().join("bundle"), &dev).unwrap();
    let run = tempfile::tempdir().unwrap();
    let omg = ModelConfig {
        side_input: true,
        input_skip: true,
        skip_taps: 3,
        skip_taps_below: Some(100),
        text_control: Some(MocConfig {
            d_control: 8,
            experts: 3,
            ..MocConfig::default()
        }),
        ..sentence_tiny()
    };
    train(
        run.path(),
        omg,
        Some(&prior_dir.path().join("bundle")),
        1e-2,
        5,
    );
    let bundle = ModelBundle::load(&run.path().join("bundle"), &dev).unwrap();
    assert!(bundle.model.has_text_control());
    let (old, new) = (tensors(&prior.model), tensors(&bundle.model));
    for (name, value) in &new {
        if name.starts_with("text_control") {
            continue;
        }
        let diff = old[name]
            .iter()
            .zip(value)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0f32, f32::max);
        assert!(diff < 2e-3, "the frozen prior's {name} moved by {diff}");
    }
    let ups: f32 = new
        .iter()
        .filter(|(k, _)| k.starts_with("text_control.blocks") && k.contains(".up."))
        .flat_map(|(_, v)| v.iter().map(|x| x.abs()))
        .sum();
    assert!(ups > 0.0, "the ControlNet's zero outputs learnt");
    // The bundle reads its prompts token by token, and the text steers only where kept.
    let text = bundle
        .text
        .batch(&["a person waves", "a person walks forward"], &dev);
    let super::prompt::TextBatch::Sentences(s) = &text else {
        panic!("sentence batch")
    };
    assert!(s.tokens.is_some());
    let model = bundle.model.clone();
    let ask = |keep: f32| {
        model.predict_x0(&DenoiserInput {
            x_t: NoiseSource::new(3).tensor([2, 8, 263], &dev),
            timesteps: vec![500, 500],
            text: text.clone(),
            keep_text: Tensor::full([2], keep, &dev),
            padding: None,
        })
    };
    let moved = (ask(1.0) - ask(0.0)).abs().max().into_scalar::<f32>();
    assert!(moved > 0.0);
}
