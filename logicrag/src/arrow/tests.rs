//! Tests of the facts and answers tables and their Parquet files.

use super::*;
use crate::ask::{AskOptions, Outcome};
use arrow_array::cast::AsArray;
use arrow_array::types::{Float64Type, Int64Type};
use arrow_array::{Array, StringArray};
use perception::{Fact, Provenance};

/// A scratch directory, removed when dropped.
struct TempDir(PathBuf);

impl TempDir {
    fn new(test: &str) -> TempDir {
        let dir =
            std::env::temp_dir().join(format!("logicrag-arrow-{}-{test}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("temp dir");
        TempDir(dir)
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Every type in `t`, nested ones included.
fn types(t: &DataType, out: &mut Vec<DataType>) {
    out.push(t.clone());
    match t {
        DataType::List(f) | DataType::LargeList(f) => types(f.data_type(), out),
        DataType::Struct(fields) => {
            for f in fields {
                types(f.data_type(), out);
            }
        }
        _ => {}
    }
}

#[test]
fn no_column_is_unsigned() {
    for schema in [facts_schema(), answers_schema()] {
        let mut all = Vec::new();
        for f in schema.fields() {
            types(f.data_type(), &mut all);
        }
        assert!(all.contains(&DataType::Int64), "{schema:?}");
        for t in &all {
            assert!(!t.is_unsigned_integer(), "{t} in {schema:?}");
        }
    }
}

fn fact(pred: &str, args: &[&str], provenance: Provenance) -> Fact {
    Fact {
        predicate: pred.into(),
        args: args.iter().map(|a| (*a).to_string()).collect(),
        provenance: Arc::new(provenance),
    }
}

fn provenance(measured: Option<f64>, threshold: Option<(&str, f64)>, note: &str) -> Provenance {
    Provenance {
        window: 3,
        frames: (30, 39),
        source: "sim:test".into(),
        measured,
        threshold: threshold.map(|(n, v)| (n.to_string(), v)),
        note: note.into(),
        probability: None,
    }
}

#[test]
fn facts_keep_their_order_and_provenance_through_parquet() {
    let facts = [
        fact(
            "Moving",
            &["car_1"],
            provenance(
                Some(3.25),
                Some(("moving_speed_vehicle_mps", 0.7)),
                "mean speed 3.25 m/s",
            ),
        ),
        fact("TypeOf", &["car_1", "Car"], provenance(None, None, "")),
        fact("Road", &[], provenance(None, None, "")),
    ];
    let place = WindowPlace {
        id: "test_000030",
        index: 3,
        first_frame: 30,
        last_frame: 39,
    };
    let input = crate::kb::WindowFacts::from(facts.to_vec());
    let mut b = FactsBuilder::new();
    b.push_window("sim:test", place, input.iter());
    assert_eq!(b.len(), 3);
    let batch = b.finish().expect("builds");
    assert!(b.is_empty());
    assert_eq!(batch.num_rows(), 3);

    let tmp = TempDir::new("facts");
    let path = tmp.0.join("facts.parquet");
    let rows = write_parquet(&path, facts_schema(), std::slice::from_ref(&batch)).expect("writes");
    assert_eq!(rows, 3);
    let back = read_parquet(&path).expect("reads");
    assert_eq!(back.len(), 1);
    let read = &back[0];
    assert_eq!(read.schema().fields(), facts_schema().fields());
    assert_eq!(read.columns(), batch.columns());

    // What the columns say, against the facts.
    let pred: &StringArray = read.column(5).as_string();
    assert_eq!(
        pred.iter().flatten().collect::<Vec<_>>(),
        ["Moving", "TypeOf", "Road"]
    );
    let args = read.column(6).as_list::<i32>();
    let arg1 = args.value(1);
    let arg1: &StringArray = arg1.as_string();
    assert_eq!(arg1.iter().flatten().collect::<Vec<_>>(), ["car_1", "Car"]);
    assert_eq!(args.value(2).len(), 0);
    let prov = read.column(7).as_struct();
    let measured = prov.column(4).as_primitive::<Float64Type>();
    assert_eq!(measured.value(0), 3.25);
    assert!(measured.is_null(1));
    let threshold = prov.column(5).as_struct();
    assert!(threshold.is_valid(0) && threshold.is_null(1));
    assert_eq!(
        threshold.column(0).as_string::<i32>().value(0),
        "moving_speed_vehicle_mps"
    );
    let note: &StringArray = prov.column(6).as_string();
    assert_eq!(note.value(0), "mean speed 3.25 m/s");
    assert!(note.is_null(1));
    let first = prov.column(1).as_primitive::<Int64Type>();
    assert_eq!(first.value(2), 30);
}

#[test]
fn answers_keep_bindings_and_proofs_through_parquet() {
    let (e, kb) = crate::json::tests::cars();
    let queries = [
        "TypeOf(x, y)",
        "Moving(x)",
        "Flying(x)",
        "TypeOf(car_4, Car)",
        "Vehicles(x) ^ ¬SpeedUp(x) ^ ¬Pedestrian(x)",
    ];
    let results: Vec<AskResult> = queries
        .iter()
        .map(|q| e.ask(&kb, &e.prepare_query(q), AskOptions::default()))
        .collect();
    assert_eq!(results[0].answer, Outcome::Yes);
    assert_eq!(results[2].answer, Outcome::Invalid);
    let mut b = AnswersBuilder::new(true);
    for (i, r) in results.iter().enumerate() {
        let question = (i == 1).then_some("Is a car moving?");
        b.push("sim:test", question, i, r);
    }
    let batch = b.finish().expect("builds");
    let tmp = TempDir::new("answers");
    let path = tmp.0.join("answers.parquet");
    write_parquet(&path, answers_schema(), std::slice::from_ref(&batch)).expect("writes");
    let back = read_parquet(&path).expect("reads");
    let read = &back[0];
    assert_eq!(read.schema().fields(), answers_schema().fields());
    assert_eq!(read.columns(), batch.columns());

    let question: &StringArray = read.column(4).as_string();
    assert!(question.is_null(0));
    assert_eq!(question.value(1), "Is a car moving?");
    let answer: &StringArray = read.column(7).as_string();
    assert_eq!(
        answer.iter().flatten().collect::<Vec<_>>(),
        ["yes", "yes", "invalid", "yes", "yes"]
    );
    let count = read.column(8).as_primitive::<Int64Type>();
    assert_eq!(count.value(0), 2);
    // Bindings: row 0 has two, each `[(x, car_…), (y, Car)]`, sorted as
    // the answer lists them.
    let bindings = read.column(10).as_list::<i32>();
    let row0 = bindings.value(0);
    let row0 = row0.as_list::<i32>();
    assert_eq!(row0.len(), 2);
    for (i, binding) in results[0].bindings.iter().enumerate() {
        let pairs = row0.value(i);
        let pairs = pairs.as_struct();
        let vars: &StringArray = pairs.column(0).as_string();
        let values: &StringArray = pairs.column(1).as_string();
        let got: Vec<(String, String)> = vars
            .iter()
            .zip(values.iter())
            .map(|(a, b)| (a.unwrap_or("").into(), b.unwrap_or("").into()))
            .collect();
        assert_eq!(&got, binding);
    }
    // A ground query: one binding with no pairs.
    assert_eq!(bindings.value(3).len(), results[3].bindings.len());
    let reasons = read.column(11).as_list::<i32>();
    assert!(!reasons.value(2).is_empty(), "invalid says why");
    // Proofs: every row reads back as the trees JSON prints.
    for (i, r) in results.iter().enumerate() {
        let trees = read_proofs(read.column(12), i)
            .expect("reads")
            .expect("with proofs");
        assert_eq!(
            serde_json::to_value(&trees).expect("json"),
            serde_json::to_value(&r.proofs).expect("json"),
            "{}",
            queries[i]
        );
    }
    // …and the nodes are typed: `Moving(x)`'s one proof is one observed
    // `Moving(car_4)`; the last query's proof ends with a negated atom.
    let nodes = |row: usize, answer: usize| {
        let rows = read.column(12).as_list::<i32>();
        let answers = rows.value(row);
        answers.as_list::<i32>().value(answer)
    };
    let moving = nodes(1, 0);
    let moving = moving.as_struct();
    let field = |s: &StructArray, name: &str| s.column_by_name(name).expect(name).clone();
    assert_eq!(moving.len(), 1);
    assert_eq!(
        field(moving, "predicate").as_string::<i32>().value(0),
        "Moving"
    );
    assert_eq!(
        field(moving, "kind").as_string::<i32>().value(0),
        "observed"
    );
    assert!(field(moving, "parent").is_null(0));
    let args = field(moving, "args");
    let args = args.as_list::<i32>().value(0);
    assert_eq!(args.as_string::<i32>().value(0), "car_4");
    assert!(field(moving, "provenance").is_valid(0));
    let not = nodes(4, 0);
    let not = not.as_struct();
    let negated = field(not, "negated");
    let negated = negated.as_boolean();
    let last = not.len() - 1;
    assert!(negated.value(last) && !negated.value(0));
    assert_eq!(
        field(not, "predicate").as_string::<i32>().value(last),
        "Pedestrian"
    );
    assert_eq!(field(not, "kind").as_string::<i32>().value(last), "absent");

    // Without proofs, the column is null.
    let mut b = AnswersBuilder::new(false);
    b.push("sim:test", None, 0, &results[0]);
    let batch = b.finish().expect("builds");
    assert!(batch.column(12).is_null(0));
    assert_eq!(read_proofs(batch.column(12), 0).expect("reads"), None);
}

/// A proof of every kind of step, nested `depth` rules deep.
fn every_step(depth: usize) -> Vec<crate::proof::ProofNode> {
    use crate::proof::{ProofNode, Step};
    let leaf = |fact: &str, step: Step| ProofNode {
        fact: fact.into(),
        step,
        premises: Vec::new(),
    };
    let seen = Arc::new(provenance(
        Some(3.25),
        Some(("moving_speed_vehicle_mps", 0.7)),
        "mean speed 3.25 m/s",
    ));
    let mut tree = leaf(
        "Moving(car_1)",
        Step::Observed {
            provenance: Some(seen),
        },
    );
    for d in 0..depth {
        tree = ProofNode {
            fact: format!("Deep{d}(car_1, \"a, b\")").into(),
            step: Step::Rule {
                line: d + 1,
                text: Arc::from(format!("Deep{d}(x, y) :- …")),
            },
            premises: vec![
                tree,
                leaf("Given()", Step::Observed { provenance: None }),
                leaf("¬Near(car_1, ped_2)", Step::Absent { doubt: Some(0.25) }),
            ],
        };
    }
    vec![
        tree,
        leaf(
            "¬∃y: (Road(y) ∧ On(ped_1, y))",
            Step::Absent { doubt: None },
        ),
        leaf(
            "Far(car_1)",
            Step::Cut {
                reason: "depth limit 64".into(),
            },
        ),
    ]
}

#[test]
fn proof_trees_of_any_depth_survive_the_proofs_column_and_parquet() {
    let answers = vec![every_step(3), Vec::new(), every_step(300)];
    let mut c = proofs::ProofColumns::new();
    c.push(Some(&answers));
    c.push(None);
    c.push(Some(&[]));
    let column = c.finish().expect("builds");
    let schema = Arc::new(Schema::new(vec![Field::new(
        "proofs",
        proofs::proofs_type(),
        true,
    )]));
    let batch = RecordBatch::try_new(schema.clone(), vec![column]).expect("batch");
    let tmp = TempDir::new("proofs");
    let path = tmp.0.join("proofs.parquet");
    write_parquet(&path, schema, std::slice::from_ref(&batch)).expect("writes");
    let back = read_parquet(&path).expect("reads");
    assert_eq!(back[0].columns(), batch.columns());
    let column = back[0].column(0);
    assert_eq!(read_proofs(column, 0).expect("reads"), Some(answers));
    assert_eq!(read_proofs(column, 1).expect("reads"), None);
    assert_eq!(read_proofs(column, 2).expect("reads"), Some(Vec::new()));
    assert!(read_proofs(column, 3).is_err(), "no such row");
    // Depth and parents: the deepest observed leaf of the 300-deep tree.
    let rows = column.as_list::<i32>();
    let deep = rows.value(0);
    let deep = deep.as_list::<i32>().value(2);
    let deep = deep.as_struct();
    let depth = deep.column_by_name("depth").expect("depth");
    let depth = depth.as_primitive::<Int64Type>();
    assert_eq!(depth.value(0), 0);
    assert_eq!(depth.value(300), 300);
    let parent = deep.column_by_name("parent").expect("parent");
    assert_eq!(parent.as_primitive::<Int64Type>().value(300), 299);
}

#[test]
fn window_ids_that_cannot_be_file_names_are_refused() {
    let dir = Path::new("/tmp/x");
    assert_eq!(
        window_file(dir, "0000_000010").expect("fine"),
        dir.join("0000_000010.parquet")
    );
    for bad in ["", "..", ".hidden", "a/b", "a\\b", "a b"] {
        assert!(window_file(dir, bad).is_err(), "{bad}");
    }
}
